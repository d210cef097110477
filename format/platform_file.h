// Internal: the one place of the runtime side that talks to the operating system about files
// (POSIX and Win32 branches in platform_file.cpp). Reads are positioned reads into memory the
// caller owns, never a mapping, so a file truncated or rewritten while open gives an error
// rather than a fault, and one file may be read from several threads at once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "common/status.h"
#include "format/byte_source.h"

namespace vt::platform {

class ReadOnlyFile final : public ByteSource {
 public:
  // Opens a regular file for reading. kNotFound when nothing is there, kInvalidArgument for a
  // directory, FIFO, device or socket (never blocks on a FIFO), kIo otherwise. The message
  // says what went wrong, not the path (callers add it).
  static Expected<std::unique_ptr<ReadOnlyFile>> open(const std::string& path);
  ~ReadOnlyFile() override;
  ReadOnlyFile(const ReadOnlyFile&) = delete;
  ReadOnlyFile& operator=(const ReadOnlyFile&) = delete;

  // The size at open.
  uint64_t size() const override { return size_; }
  // Reads up to out.size() bytes at `offset`; returns the count read, 0 at the end of the file
  // (kIo with the system's message on failure). Safe to call from several threads.
  Expected<size_t> read_some(uint64_t offset, std::span<uint8_t> out) const override;

 private:
  ReadOnlyFile() = default;
  intptr_t handle_ = -1;  // a file descriptor (POSIX) or a HANDLE (Win32)
  uint64_t size_ = 0;
};

}  // namespace vt::platform
