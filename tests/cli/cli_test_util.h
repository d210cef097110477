// Runs the built vtbake binary (VTBAKE_BINARY) for the end-to-end CLI tests.
#pragma once

#include <sys/wait.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace vt::testing {

struct RunResult {
  int exit_code = -1;
  std::string out;
};

// A shell command line's stdout and exit status.
inline RunResult run_command(const std::string& command) {
  RunResult r;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// `vtbake ARGS`; with merge_stderr the output holds stderr too, else stderr is discarded (so
// that --json output parses).
inline RunResult run_vtbake(const std::string& args, bool merge_stderr) {
  return run_command(std::string(VTBAKE_BINARY) + " " + args +
                     (merge_stderr ? " 2>&1" : " 2>/dev/null"));
}

// A file's bytes ("" when it cannot be read).
inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// An empty folder for one test suite: TMP/vt_NAME_PID.
inline std::string fresh_test_dir(const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("vt_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}
// Removes a suite's folder; VTBAKE_KEEP_TEST_OUTPUT=1 keeps the scenes, bakes, images and
// reports for inspection.
inline void remove_test_dir(const std::string& dir) {
  if (!std::getenv("VTBAKE_KEEP_TEST_OUTPUT")) std::filesystem::remove_all(dir);
}

// The small sample scenes of the CLI tests: `vtbake sample-scene DIR` with 2 ground cells, 8
// sphere segments and 32-texel textures (or `flags`). "" on success, else what went wrong.
inline std::string write_sample_scene(
    const std::string& dir,
    const std::string& flags = "--ground-cells 2 --sphere-segments 8 --texture-size 32") {
  const RunResult s = run_vtbake("-q sample-scene " + dir + " " + flags, true);
  return s.exit_code == 0 ? "" : "sample-scene failed: " + s.out;
}

}  // namespace vt::testing
