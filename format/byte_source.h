// Where a page-file reader's bytes come from: a file (PageFileReader::open(path)) or storage the
// engine owns (pak files, virtual file systems, network), given as a ByteSource.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "common/status.h"

namespace vt {

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Total bytes; read once when the reader opens.
  virtual uint64_t size() const = 0;
  // Reads up to out.size() bytes at `offset`: the count read (0 at the end), or an error. Called
  // from several threads at once (the runtime's loader threads).
  virtual Expected<size_t> read_some(uint64_t offset, std::span<uint8_t> out) const = 0;
};

}  // namespace vt
