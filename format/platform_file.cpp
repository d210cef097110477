#include "format/platform_file.h"

#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#ifndef NOMINMAX
#define NOMINMAX
#endif
#include <windows.h>
#else
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#endif

#include <algorithm>

namespace vt::platform {

#ifdef _WIN32

namespace {

std::string last_error_text() {
  char buf[256] = {};
  FormatMessageA(FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, nullptr,
                 GetLastError(), 0, buf, sizeof buf, nullptr);
  std::string text = buf;
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

// UTF-8 path to the wide form Win32 takes.
std::wstring widen(const std::string& path) {
  const int n = MultiByteToWideChar(CP_UTF8, 0, path.c_str(), -1, nullptr, 0);
  std::wstring wide(size_t(std::max(n, 1)), L'\0');
  MultiByteToWideChar(CP_UTF8, 0, path.c_str(), -1, wide.data(), n);
  wide.resize(wide.size() - 1);
  return wide;
}

}  // namespace

Expected<std::unique_ptr<ReadOnlyFile>> ReadOnlyFile::open(const std::string& path) {
  HANDLE h = CreateFileW(widen(path).c_str(), GENERIC_READ,
                         FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE, nullptr,
                         OPEN_EXISTING, FILE_ATTRIBUTE_NORMAL, nullptr);
  if (h == INVALID_HANDLE_VALUE) {
    const DWORD err = GetLastError();
    const ErrorCode code = err == ERROR_FILE_NOT_FOUND || err == ERROR_PATH_NOT_FOUND
                               ? ErrorCode::kNotFound
                               : ErrorCode::kIo;
    return Error(code, "cannot open: " + last_error_text());
  }
  std::unique_ptr<ReadOnlyFile> file(new ReadOnlyFile);
  file->handle_ = reinterpret_cast<intptr_t>(h);
  if (GetFileType(h) != FILE_TYPE_DISK)
    return Error(ErrorCode::kInvalidArgument, "not a regular file (a device or pipe)");
  LARGE_INTEGER size;
  if (!GetFileSizeEx(h, &size)) return Error(ErrorCode::kIo, "cannot stat: " + last_error_text());
  file->size_ = uint64_t(size.QuadPart);
  return file;
}

ReadOnlyFile::~ReadOnlyFile() {
  if (handle_ != -1) CloseHandle(reinterpret_cast<HANDLE>(handle_));
}

Expected<size_t> ReadOnlyFile::read_some(uint64_t offset, std::span<uint8_t> out) const {
  // ReadFile with an OVERLAPPED offset on a synchronous handle is a positioned read that leaves
  // no shared file pointer behind, so threads do not race.
  OVERLAPPED at = {};
  at.Offset = DWORD(offset);
  at.OffsetHigh = DWORD(offset >> 32);
  DWORD n = 0;
  const DWORD want = DWORD(std::min<size_t>(out.size(), 1u << 30));
  if (!ReadFile(reinterpret_cast<HANDLE>(handle_), out.data(), want, &n, &at)) {
    if (GetLastError() == ERROR_HANDLE_EOF) return size_t(0);
    return Error(ErrorCode::kIo, "read failed: " + last_error_text());
  }
  return size_t(n);
}

#else

namespace {

const char* file_kind_name(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

}  // namespace

Expected<std::unique_ptr<ReadOnlyFile>> ReadOnlyFile::open(const std::string& path) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const ErrorCode code = errno == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIo;
    return Error(code, std::string("cannot open: ") + std::strerror(errno));
  }
  std::unique_ptr<ReadOnlyFile> file(new ReadOnlyFile);
  file->handle_ = fd;
  struct stat st;
  if (::fstat(fd, &st) != 0) return Error(ErrorCode::kIo, "cannot stat");
  if (!S_ISREG(st.st_mode))
    return Error(ErrorCode::kInvalidArgument,
                 std::string("not a regular file (") + file_kind_name(st.st_mode) + ")");
  file->size_ = uint64_t(st.st_size);
  return file;
}

ReadOnlyFile::~ReadOnlyFile() {
  if (handle_ >= 0) ::close(int(handle_));
}

Expected<size_t> ReadOnlyFile::read_some(uint64_t offset, std::span<uint8_t> out) const {
  for (;;) {
    const ssize_t n = ::pread(int(handle_), out.data(), out.size(), off_t(offset));
    if (n >= 0) return size_t(n);
    if (errno != EINTR)
      return Error(ErrorCode::kIo, std::string("read failed: ") + std::strerror(errno));
  }
}

#endif

}  // namespace vt::platform
