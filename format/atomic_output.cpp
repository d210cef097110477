// Output path resolution and staged outputs replaced together (see atomic_output.h).
#include "format/atomic_output.h"

#include <fcntl.h>
#include <limits.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace vt {

namespace {

std::string errno_text() {
  return std::strerror(errno);
}

std::string dir_of(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

void sync_dir(const std::string& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

Status sync_file(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Error(ErrorCode::kIo, path + ": cannot open to sync: " + errno_text());
  const bool ok = ::fsync(fd) == 0;
  const std::string err = ok ? std::string() : errno_text();
  ::close(fd);
  return ok ? Status::Ok() : Error(ErrorCode::kIo, path + ": fsync failed: " + err);
}

}  // namespace

Expected<std::string> resolve_output_path(const std::string& path) {
  if (path.empty()) return Error(ErrorCode::kInvalidArgument, "empty output path");
  std::string p = path;
  for (int hops = 0; hops <= 40; ++hops) {
    struct stat st;
    if (::lstat(p.c_str(), &st) != 0) {
      if (errno == ENOENT) return p;  // a new file; its folder is checked when it is created
      return Error(ErrorCode::kIo, path + ": cannot inspect the output path: " + errno_text());
    }
    if (S_ISREG(st.st_mode)) return p;
    if (!S_ISLNK(st.st_mode)) {
      const std::string where = p == path ? path : path + " (a link to " + p + ")";
      return Error(ErrorCode::kInvalidArgument,
                   where + " is " + kind_of(st.st_mode) + ": refusing to replace it with a file");
    }
    char target[PATH_MAX];
    const ssize_t n = ::readlink(p.c_str(), target, sizeof target - 1);
    if (n < 0) return Error(ErrorCode::kIo, path + ": cannot read the link: " + errno_text());
    std::string next(target, size_t(n));
    p = next.front() == '/' ? next : dir_of(p) + "/" + next;
  }
  return Error(ErrorCode::kInvalidArgument, path + ": too many levels of symbolic links");
}

Status check_input_file(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    const ErrorCode code = errno == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIo;
    return Error(code, path + ": cannot open: " + errno_text());
  }
  if (!S_ISREG(st.st_mode))
    return Error(ErrorCode::kInvalidArgument,
                 path + " is " + kind_of(st.st_mode) + ", not a regular file to read");
  return Status::Ok();
}

OutputSet::~OutputSet() {
  if (committed_) return;
  for (const Staged& s : staged_) ::unlink(s.temp.c_str());
}

Expected<std::string> OutputSet::stage(const std::string& final_path) {
  if (committed_) return Error(ErrorCode::kInvalidArgument, final_path + ": outputs committed");
  VT_ASSIGN_OR_RETURN(std::string target, resolve_output_path(final_path));
  std::string temp = target + ".tmp-XXXXXX";
  const int fd = ::mkstemp(temp.data());
  if (fd < 0)
    return Error(ErrorCode::kIo, final_path + ": cannot create temporary file: " + errno_text());
  ::close(fd);
  staged_.push_back({final_path, std::move(target), temp});
  return temp;
}

Status OutputSet::commit() {
  if (committed_) return Status::Ok();
  // mkstemp creates 0600; outputs are ordinary build results.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  for (const Staged& s : staged_) {
    VT_RETURN_IF_ERROR(sync_file(s.temp));
    ::chmod(s.temp.c_str(), 0666 & ~mask);
  }
  // Hard links keep the previous files reachable until every rename has succeeded, so a failed
  // rename can put them back. A file system without hard links just loses that undo.
  std::vector<std::string> backups(staged_.size());
  std::vector<bool> existed(staged_.size());
  for (size_t i = 0; i < staged_.size(); ++i) {
    struct stat st;
    existed[i] = ::lstat(staged_[i].target.c_str(), &st) == 0;
    if (!existed[i]) continue;
    std::string backup = staged_[i].target + ".old-XXXXXX";
    const int fd = ::mkstemp(backup.data());
    if (fd < 0) continue;
    ::close(fd);
    ::unlink(backup.c_str());
    if (::link(staged_[i].target.c_str(), backup.c_str()) == 0) backups[i] = backup;
  }
  auto drop_backups = [&] {
    for (const std::string& b : backups)
      if (!b.empty()) ::unlink(b.c_str());
  };
  for (size_t i = 0; i < staged_.size(); ++i) {
    if (::rename(staged_[i].temp.c_str(), staged_[i].target.c_str()) == 0) continue;
    const Status error = Error(
        ErrorCode::kIo, staged_[i].final_path + ": rename into place failed: " + errno_text());
    for (size_t j = 0; j < i; ++j) {
      if (!backups[j].empty()) {
        if (::rename(backups[j].c_str(), staged_[j].target.c_str()) == 0) backups[j].clear();
      } else if (!existed[j]) {
        ::unlink(staged_[j].target.c_str());
      }
    }
    for (size_t j = i; j < staged_.size(); ++j) ::unlink(staged_[j].temp.c_str());
    drop_backups();
    committed_ = true;  // nothing staged is left to remove
    return error;
  }
  committed_ = true;
  drop_backups();
  for (const Staged& s : staged_) sync_dir(dir_of(s.target));
  return Status::Ok();
}

}  // namespace vt
