// What every fuzz target shares: the importers and readers under test take a path, so each input
// is written to a file in a folder of the process's own (on tmpfs where there is one), and the
// checks a target makes on every error it gets back.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "common/status.h"

namespace vt::fuzz {

// The process's scratch folder, removed at exit. Held in a buffer that is never destroyed: the
// exit handler runs after function-local statics are gone.
inline const std::string& scratch_dir() {
  static const std::string& dir = *new std::string([] {
    const char* base = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
    std::string tmpl = std::string(base) + "/vtbake_fuzz_XXXXXX";
    if (!::mkdtemp(tmpl.data())) std::abort();
    return tmpl + "/";
  }());
  static const bool cleanup = [] {
    return std::atexit([] {
             std::error_code ec;
             std::filesystem::remove_all(scratch_dir(), ec);
           }) == 0;
  }();
  (void)cleanup;
  return dir;
}

// Writes `bytes` to NAME in the scratch folder (replacing it) and returns the file's path.
inline std::string write_input(const std::string& name, std::string_view bytes) {
  const std::string path = scratch_dir() + name;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) std::abort();
  for (size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n <= 0) std::abort();
    done += size_t(n);
  }
  ::close(fd);
  return path;
}

inline std::string_view as_text(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// A failure the fuzzer reports: libFuzzer saves the input that led to it.
[[noreturn]] inline void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz finding: %s: %s\n", what, detail.c_str());
  std::abort();
}

// Hostile input may be refused, but only as input: never an internal error, never a message
// that does not say which file it is about.
inline void check_refusal(const Status& status, const std::string& path) {
  if (status.ok()) return;
  if (status.code() == ErrorCode::kInternal) finding("internal error", status.message());
  if (status.message().find(path) == std::string::npos)
    finding("error does not name the file", status.message());
}

}  // namespace vt::fuzz
