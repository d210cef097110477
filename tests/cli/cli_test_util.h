// Runs the built vtbake binary (VTBAKE_BINARY) for the end-to-end CLI tests.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

namespace vt::testing {

struct RunResult {
  int exit_code = -1;
  std::string out;
};

// `vtbake ARGS`; with merge_stderr the output holds stderr too, else stderr is discarded (so
// that --json output parses).
inline RunResult run_vtbake(const std::string& args, bool merge_stderr) {
  RunResult r;
  const std::string command =
      std::string(VTBAKE_BINARY) + " " + args + (merge_stderr ? " 2>&1" : " 2>/dev/null");
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// A file's bytes ("" when it cannot be read).
inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace vt::testing
