#include "input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace tender {
namespace {

std::string mib(uint64_t bytes) {
  return bytes >= (1u << 20) ? std::to_string(bytes >> 20) + " MiB" : std::to_string(bytes) + " bytes";
}

const char* kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "it is a folder";
  if (S_ISFIFO(mode)) return "it is not a regular file (a FIFO)";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "it is not a regular file (a device)";
  if (S_ISSOCK(mode)) return "it is not a regular file (a socket)";
  return "it is not a regular file";
}

std::string tooLarge(uint64_t max_bytes) { return "it is larger than " + mib(max_bytes) + ", the limit for this file"; }

} // namespace

std::optional<std::string> readInputFile(const std::string& path, uint64_t max_bytes, std::string& text) {
  if (path.empty()) return std::string("the path is empty");
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return std::strerror(errno);
  if (!S_ISREG(st.st_mode)) return kindOf(st.st_mode);
  if (uint64_t(st.st_size) > max_bytes) return tooLarge(max_bytes);
  // O_NONBLOCK: should the path become a FIFO between the check and the open, the open does not wait.
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return std::strerror(errno);
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const int saved = errno;
    close(fd);
    return std::string(S_ISREG(st.st_mode) ? std::strerror(saved) : kindOf(st.st_mode));
  }
  text.clear();
  text.reserve(size_t(st.st_size));
  char buf[65536];
  for (;;) {
    const ssize_t got = read(fd, buf, sizeof(buf));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      const int saved = errno;
      close(fd);
      return std::strerror(saved);
    }
    if (got == 0) break;
    if (text.size() + size_t(got) > max_bytes) {
      close(fd);
      return tooLarge(max_bytes);
    }
    text.append(buf, size_t(got));
  }
  close(fd);
  return std::nullopt;
}

bool sameFile(const std::string& a, const std::string& b) {
  struct stat sa {
  }, sb{};
  return !a.empty() && !b.empty() && stat(a.c_str(), &sa) == 0 && stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

} // namespace tender
