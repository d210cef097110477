// Output and input paths that hostile or careless arguments cannot turn against the machine:
// an output replaces only a regular file (or a symlink's regular target), only once complete,
// and a set of outputs (a bake's .vtpf and .glb) is replaced together. docs/FORMAT.md,
// "Writing outputs", states the rules every `-o` follows.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "common/status.h"

namespace vt {

// Where writing `path` lands. `path` itself when nothing or a regular file is there; the final
// target of a symlink (followed through any chain, relative links from their own folder), so
// that the target is replaced in its own folder and the link stays a link. A directory,
// device, FIFO or socket at the path (or at the link's target) gives kInvalidArgument naming
// the path and what is there: a writer never replaces what is not a file.
Expected<std::string> resolve_output_path(const std::string& path);

// Ok when `path` names a regular file (symlinks followed), without opening it: opening a FIFO
// blocks until a writer comes, a device never ends. kNotFound when nothing is there,
// kInvalidArgument naming what is there otherwise.
Status check_input_file(const std::string& path);

// Staging files: every temporary a writer puts beside its target is named
// TARGET.tmp-PID@HOST-XXXXXX (TARGET.old-PID@HOST-XXXXXX for commit()'s backups), so that a
// later writer can tell one abandoned by a killed process from a live writer's. HOST is the
// host name up to its first dot (letters, digits and '-', at most 32).
struct StagingFile {
  int fd = -1;  // open for writing, mode 0600; the caller closes it
  std::string path;
};
// Sweeps `target`'s stale staging files (sweep_stale_staging), then creates a new one beside
// it; `kind` is "tmp" or "old". Errors name `target`.
Expected<StagingFile> create_staging_file(const std::string& target, const char* kind = "tmp");

// Removes the staging files of `target` (only names of the pattern above, and staging files of
// those, as a bake's page writer stages beside its own staged file) whose owner is gone: the
// PID on this host is not running, or runs a process started after the file was last written
// (a reused PID). Files from another host, and from writers before the PID was in the name
// (TARGET.tmp-XXXXXX), are removed when untouched for kStaleStagingSeconds. A live writer's
// file is never removed, whatever its age. Best effort: returns how many it removed.
constexpr int64_t kStaleStagingSeconds = 24 * 3600;
int sweep_stale_staging(const std::string& target);

// sweep_stale_staging for every target in `dir` (not below it): `vtbake clean DIR`. Returns
// the paths removed; kNotFound/kIo when the folder cannot be read.
Expected<std::vector<std::string>> sweep_stale_staging_in(const std::string& dir);

// Outputs staged under temporary names beside their final targets and renamed into place
// together by commit(): both or neither for an error anywhere before or during commit. What
// stays: a kill in the few microseconds between two renames of commit() leaves the first
// replaced and not the second (POSIX has no multi-file rename). Uncommitted staged files are
// removed by the destructor. Not thread-safe.
class OutputSet {
 public:
  OutputSet() = default;
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // Checks `final_path` (resolve_output_path) and creates an empty temporary file beside its
  // target; returns the temporary's path, which the caller writes (or renames a file onto).
  Expected<std::string> stage(const std::string& final_path);
  // Syncs every staged file and renames each over its target, in staging order. If a rename
  // fails, the targets already replaced get their previous files back (or are removed when
  // there were none) and the error names the path.
  Status commit();

 private:
  struct Staged {
    std::string final_path;  // as the caller named it (messages)
    std::string target;      // resolve_output_path(final_path)
    std::string temp;
  };
  std::vector<Staged> staged_;
  bool committed_ = false;
};

// Writes all `size` bytes to `fd` (write() may move fewer, or be interrupted); an error names
// `path`.
Status write_all(int fd, const void* data, size_t size, const std::string& path);

// The one way a single output file is written: `write` fills the temporary path it is given
// (beside the target, OutputSet::stage); when it succeeds the file is synced and renamed over
// `path`, else the temporary is removed and `path` keeps what it had. A full disk or a kill
// never leaves a truncated file under the final name.
Status write_output(const std::string& path,
                    const std::function<Status(const std::string& temp)>& write);
// write_output of `bytes`, every write checked.
Status write_output_bytes(const std::string& path, std::string_view bytes);

}  // namespace vt
