// Output path resolution and staged outputs replaced together (see atomic_output.h).
#include "format/atomic_output.h"

#include <dirent.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string_view>

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

// The host part of staging names: the name up to its first dot, only characters that cannot
// be mistaken for the pattern's separators.
const std::string& host_tag() {
  static const std::string tag = [] {
    char buf[256] = {};
    std::string h;
    if (::gethostname(buf, sizeof buf - 1) == 0)
      for (const char* c = buf; *c != 0 && *c != '.' && h.size() < 32; ++c)
        if (std::isalnum(static_cast<unsigned char>(*c)) || *c == '-') h += *c;
    return h.empty() ? std::string("localhost") : h;
  }();
  return tag;
}

bool all_alnum(std::string_view s) {
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) return false;
  return !s.empty();
}

struct StagingOwner {
  bool tagged = false;  // PID@HOST in the name (else a writer from before it was)
  long pid = 0;
  std::string_view host;
};

// Parses one staging suffix of `name` at `pos` (".tmp-" or ".old-", then PID@HOST- or nothing,
// then mkstemp's 6 characters) and moves `pos` past it; false if there is none.
bool parse_staging_suffix(std::string_view name, size_t& pos, StagingOwner& owner) {
  const std::string_view rest = name.substr(pos);
  if (rest.substr(0, 5) != ".tmp-" && rest.substr(0, 5) != ".old-") return false;
  const std::string_view body = rest.substr(5, rest.find('.', 5) - 5);
  pos += 5 + body.size();
  owner = {};
  if (body.size() == 6) return all_alnum(body);
  const size_t at = body.find('@');
  if (at == std::string_view::npos || at == 0 || at > 9 || body.size() < at + 9) return false;
  const std::string_view pid = body.substr(0, at), tail = body.substr(at + 1);
  for (char c : pid)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  if (tail[tail.size() - 7] != '-' || !all_alnum(tail.substr(tail.size() - 6))) return false;
  owner.host = tail.substr(0, tail.size() - 7);
  for (char c : owner.host)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-') return false;
  owner.tagged = true;
  owner.pid = std::stol(std::string(pid));
  return owner.pid > 0;
}

// When process `pid` started, in seconds since the epoch (-1 if unknown): /proc/PID/stat's
// start time in clock ticks after boot, plus /proc/stat's boot time.
int64_t process_start_time(long pid) {
  char path[64];
  std::snprintf(path, sizeof path, "/proc/%ld/stat", pid);
  FILE* f = std::fopen(path, "r");
  if (!f) return -1;
  char line[1024] = {};
  const size_t n = std::fread(line, 1, sizeof line - 1, f);
  std::fclose(f);
  // Fields after the command name (which may hold spaces and parentheses): the start time is
  // field 22, the 20th after ")".
  const char* p = std::strrchr(line, ')');
  if (!p || n == 0) return -1;
  unsigned long long ticks = 0;
  int field = 2;
  for (const char* c = p + 1; *c != 0 && field < 22; ++c)
    if (*c == ' ' && ++field == 22) ticks = std::strtoull(c + 1, nullptr, 10);
  if (field != 22) return -1;
  f = std::fopen("/proc/stat", "r");
  if (!f) return -1;
  long long boot = -1;
  char key[64];
  while (std::fscanf(f, "%63s", key) == 1)
    if (std::strcmp(key, "btime") == 0 && std::fscanf(f, "%lld", &boot) == 1) break;
  std::fclose(f);
  const long hz = ::sysconf(_SC_CLK_TCK);
  return boot < 0 || hz <= 0 ? -1 : int64_t(boot) + int64_t(ticks / (unsigned long long)hz);
}

bool staging_is_stale(const StagingOwner& owner, const struct stat& st) {
  if (owner.tagged && owner.host == host_tag()) {
    if (::kill(pid_t(owner.pid), 0) != 0) return errno == ESRCH;
    // The PID runs: the owner only if it started before the file was last written (2 s
    // for the boot time's whole seconds).
    const int64_t started = process_start_time(owner.pid);
    return started >= 0 && started > int64_t(st.st_mtime) + 2;
  }
  return int64_t(std::time(nullptr)) - int64_t(st.st_mtime) > kStaleStagingSeconds;
}

}  // namespace

int sweep_stale_staging(const std::string& target) {
  const size_t slash = target.rfind('/');
  const std::string dir = dir_of(target);
  const std::string base = slash == std::string::npos ? target : target.substr(slash + 1);
  DIR* d = ::opendir(dir.c_str());
  if (!d) return 0;
  int removed = 0;
  while (const dirent* e = ::readdir(d)) {
    const std::string_view name = e->d_name;
    if (name.size() <= base.size() || name.substr(0, base.size()) != base) continue;
    // The first suffix names the owner; any after it are staging files of its own staging
    // file (a bake's page writer), so the same process's.
    size_t pos = base.size();
    StagingOwner owner, inner;
    bool ours = parse_staging_suffix(name, pos, owner);
    while (ours && pos < name.size()) ours = parse_staging_suffix(name, pos, inner);
    if (!ours) continue;
    const std::string path = dir + "/" + std::string(name);
    struct stat st;
    if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    if (staging_is_stale(owner, st) && ::unlink(path.c_str()) == 0) ++removed;
  }
  ::closedir(d);
  return removed;
}

Expected<StagingFile> create_staging_file(const std::string& target, const char* kind) {
  sweep_stale_staging(target);
  StagingFile f;
  f.path = target + "." + kind + "-" + std::to_string(::getpid()) + "@" + host_tag() + "-XXXXXX";
  f.fd = ::mkstemp(f.path.data());
  if (f.fd < 0)
    return Error(ErrorCode::kIo, target + ": cannot create temporary file: " + errno_text());
  return f;
}

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
  auto temp = create_staging_file(target);
  if (!temp.ok()) return temp.status();
  ::close(temp->fd);
  staged_.push_back({final_path, std::move(target), temp->path});
  return temp->path;
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
    auto backup = create_staging_file(staged_[i].target, "old");
    if (!backup.ok()) continue;
    ::close(backup->fd);
    ::unlink(backup->path.c_str());
    if (::link(staged_[i].target.c_str(), backup->path.c_str()) == 0) backups[i] = backup->path;
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

Status write_output(const std::string& path,
                    const std::function<Status(const std::string& temp)>& write) {
  OutputSet outputs;
  VT_ASSIGN_OR_RETURN(std::string temp, outputs.stage(path));
  VT_RETURN_IF_ERROR(write(temp));
  return outputs.commit();
}

Status write_all(int fd, const void* data, size_t size, const std::string& path) {
  const auto* p = static_cast<const uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return Error(ErrorCode::kIo, path + ": write failed: " + errno_text());
    p += n;
    size -= size_t(n);
  }
  return Status::Ok();
}

Status write_output_bytes(const std::string& path, std::string_view bytes) {
  return write_output(path, [&](const std::string& temp) -> Status {
    const int fd = ::open(temp.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0) return Error(ErrorCode::kIo, path + ": cannot open for writing: " + errno_text());
    if (Status s = write_all(fd, bytes.data(), bytes.size(), path); !s.ok()) {
      ::close(fd);
      return s;
    }
    if (::close(fd) != 0) return Error(ErrorCode::kIo, path + ": write failed: " + errno_text());
    return Status::Ok();
  });
}

Expected<std::vector<std::string>> sweep_stale_staging_in(const std::string& dir) {
  DIR* d = ::opendir(dir.c_str());
  if (!d) {
    const ErrorCode code = errno == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIo;
    return Error(code, dir + ": cannot read the folder: " + errno_text());
  }
  // The targets: every name with its first staging suffix cut off.
  std::vector<std::string> before, targets;
  while (const dirent* e = ::readdir(d)) {
    const std::string_view name = e->d_name;
    for (size_t at = name.find(".tmp-"), old = name.find(".old-");
         at != std::string_view::npos || old != std::string_view::npos;) {
      const size_t cut = std::min(at, old);
      StagingOwner owner;
      size_t pos = cut;
      // Every cut that parses is a candidate (a target's own name may hold ".tmp-"); the
      // sweep of each decides by the whole name.
      if (cut > 0 && parse_staging_suffix(name, pos, owner))
        targets.push_back(dir + "/" + std::string(name.substr(0, cut)));
      at = name.find(".tmp-", cut + 1), old = name.find(".old-", cut + 1);
    }
    before.push_back(std::string(name));
  }
  ::closedir(d);
  std::sort(targets.begin(), targets.end());
  targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
  for (const std::string& t : targets) sweep_stale_staging(t);
  std::vector<std::string> removed;
  for (const std::string& name : before) {
    struct stat st;
    const std::string path = dir + "/" + name;
    if (name != "." && name != ".." && ::lstat(path.c_str(), &st) != 0) removed.push_back(path);
  }
  return removed;
}

}  // namespace vt
