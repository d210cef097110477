// Flag parsing and exit-code rules shared by the subcommands, so that every command spells a
// codec, a memory size and an error's exit status the same way.
#pragma once

#include <cstdint>
#include <string>

#include "bake/page_encoder.h"
#include "common/status.h"

namespace vt::cli {

// kExitBadInput for errors in what the user gave (flags, missing or malformed input), else
// kExitFailure (the work itself failed: a write, a resource limit, an internal error).
int exit_code_for(const Status& status);

// Prints "vtbake COMMAND: MESSAGE" on stderr and returns exit_code_for(status).
int report_error(const char* command, const Status& status);

// --codec: dct, dct:QUALITY (1..100), bc, bc:high, bc:fast, raw.
Status parse_codec(const std::string& text, PageEncoderOptions* options);

// --memory-limit and other byte sizes: a positive number with an optional K, M or G (KiB, MiB,
// GiB) suffix; no suffix means bytes.
Status parse_byte_size(const std::string& text, uint64_t* bytes);

}  // namespace vt::cli
