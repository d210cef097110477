// Folders a test process makes under the system temp folder, removed when the process exits, so
// that a run of the suite leaves nothing behind (VTBAKE_KEEP_TEST_OUTPUT=1 keeps them to look at).
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>

namespace vt::test {

class ProcessTempDirs {
 public:
  ~ProcessTempDirs() {
    if (std::getenv("VTBAKE_KEEP_TEST_OUTPUT")) return;
    std::error_code ec;
    for (const auto& d : dirs_) std::filesystem::remove_all(d, ec);
  }
  std::filesystem::path make(const std::string& name) {
    auto d = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
    std::lock_guard<std::mutex> lock(mutex_);
    dirs_.insert(d);
    return d;
  }

 private:
  std::mutex mutex_;
  std::set<std::filesystem::path> dirs_;
};
inline ProcessTempDirs process_temp_dirs;

// TMP/NAME_PID (not created here), removed with everything below it when the process exits.
inline std::filesystem::path process_temp_dir(const std::string& name) {
  return process_temp_dirs.make(name);
}

}  // namespace vt::test
