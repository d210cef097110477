// Flag parsing and exit-code rules shared by the subcommands, so that every command spells a
// codec, a memory size and an error's exit status the same way.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "bake/page_encoder.h"
#include "common/status.h"

namespace vt::cli {

// The one exit-code rule for a failed Status, used by every command: kExitBadInput for errors
// in what the user gave (kInvalidArgument, kNotFound, kCorrupt, kUnsupported: a flag, a missing
// or malformed input, no Vulkan device), else kExitFailure (the work itself failed: kIo on a
// write, kResourceLimit, kCancelled, kInternal). A check that runs and finds a fault (a bad page,
// a view below its bounds) is kExitFailure too, chosen by the command.
int exit_code_for(const Status& status);

// Prints "vtbake COMMAND: MESSAGE" on stderr (and, with --json, the error object on stdout:
// cli/json_output.h) and returns exit_code_for(status). Every command reports a failed Status
// through this, and prints nothing else for that failure.
int report_error(const char* command, const Status& status);

// Prints "vtbake COMMAND: MESSAGE" on stderr (with --json, an error object with code "usage"
// on stdout) and returns kExitBadInput (a wrong flag or input).
int bad_usage(const char* command, const std::string& message);

// One status line on stderr, redrawn in place at most 5 times a second. Silent with --quiet
// and when stderr is not a terminal, so that logs do not fill with carriage returns.
class ProgressLine {
 public:
  explicit ProgressLine(bool quiet);
  // Whether a redraw is due now; always when `force` (a stage change, the last update).
  bool due(bool force);
  double elapsed_seconds() const;
  void print(const char* format, ...) __attribute__((format(printf, 2, 3)));
  // Ends the line so that what follows starts on its own line.
  void done();

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  Clock::time_point start_, last_{};
};

// --codec: dct, dct:QUALITY (1..100), bc, bc:high, bc:fast, raw.
Status parse_codec(const std::string& text, PageEncoderOptions* options);

// An input named "procedural:WIDTHxHEIGHT" (the generated sample pattern, no file): both sides
// plain decimal integers 1..2^24 with nothing after them. A negative, zero, huge or malformed
// size is kInvalidArgument naming the text (sscanf's %u read "-5" as 4294967291).
Status parse_procedural_size(const std::string& text, uint32_t* width, uint32_t* height);

// --memory-limit and other byte sizes: a positive number with an optional K, M or G (KiB, MiB,
// GiB) suffix; no suffix means bytes.
Status parse_byte_size(const std::string& text, uint64_t* bytes);
// The shortest exact spelling parse_byte_size reads back: 8G, 512M, 64K or plain bytes.
std::string format_byte_size(uint64_t bytes);

}  // namespace vt::cli
