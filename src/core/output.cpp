#include "output.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "input_file.h"

namespace tender {
namespace {

namespace fs = std::filesystem;

std::string cannotWrite(const std::string& path, const std::string& why) {
  return "cannot write '" + path + "': " + why;
}

std::string folderOf(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

// True when the path names something that exists and is not a regular file (a device, a pipe):
// such outputs are written in place.
bool isSpecial(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

// Writes through `write` to `f`, then flushes and closes it; false (errno set) on any failure.
bool writeAndClose(std::FILE* f, const FileWriter& write, bool sync) {
  bool ok = write(f);
  int saved = ok ? 0 : errno;
  if (std::fflush(f) != 0 || std::ferror(f)) ok = false, saved = saved ? saved : errno;
  if (ok && sync && fsync(fileno(f)) != 0 && errno != EINVAL) ok = false, saved = errno;
  if (std::fclose(f) != 0 && ok) ok = false, saved = errno;
  if (!ok) errno = saved ? saved : EIO;
  return ok;
}

mode_t fileMode() {
  const mode_t mask = umask(0);
  umask(mask);
  return 0666 & ~mask;
}

// This host's name as it appears in temporary file names: at most 16 letters, digits and '_'.
const std::string& hostTag() {
  static const std::string tag = [] {
    char name[256] = {};
    if (gethostname(name, sizeof(name) - 1) != 0 || !name[0]) return std::string("host");
    std::string t;
    for (const char* c = name; *c && t.size() < 16; ++c) t += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
    return t;
  }();
  return tag;
}

// The process that wrote a temporary file named `.NAME.tmp.HOST-PID.XXXXXX`, when HOST is this
// host; 0 otherwise.
pid_t writerOf(const std::string& name) {
  const std::string host = ".tmp." + hostTag() + "-";
  const size_t at = name.rfind(host);
  if (name.empty() || name[0] != '.' || at == std::string::npos || name.size() < at + host.size() + 8) return 0;
  const std::string rest = name.substr(at + host.size()); // PID.XXXXXX
  const size_t dot = rest.find('.');
  if (dot == std::string::npos || dot == 0 || rest.size() - dot != 7) return 0;
  pid_t pid = 0;
  for (size_t k = 0; k < dot; ++k) {
    if (!std::isdigit(static_cast<unsigned char>(rest[k])) || pid > 99999999) return 0;
    pid = pid * 10 + (rest[k] - '0');
  }
  return pid;
}

// Removes the temporary files in `folder` of processes of this host that no longer run.
void removeStaleTemps(const std::string& folder) {
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const pid_t pid = writerOf(it->path().filename().string());
    if (pid > 0 && kill(pid, 0) != 0 && errno == ESRCH && it->is_regular_file(ec)) fs::remove(it->path(), ec);
  }
}

// Creates the temporary file of `path` beside it, with the mode a new file gets; its descriptor,
// or -1 (errno set).
int makeTemp(const std::string& path, std::string& temp) {
  std::string name = ".";
  name += fs::path(path).filename().string();
  name += ".tmp." + hostTag() + "-" + std::to_string(getpid()) + ".XXXXXX";
  temp = (fs::path(folderOf(path)) / name).string();
  const int fd = mkstemp(temp.data());
  if (fd < 0) return -1;
  if (fchmod(fd, fileMode()) != 0) {
    const int saved = errno;
    close(fd);
    std::remove(temp.c_str());
    errno = saved;
    return -1;
  }
  return fd;
}

} // namespace

std::optional<std::string> checkOutputPath(const std::string& path) {
  if (path.empty()) return std::string("an output path is empty");
  // (from Python: the system would take the path as ending at the NUL, another file)
  if (path.find('\0') != std::string::npos) return cannotWrite(path, "a path cannot hold a NUL");
  struct stat st {};
  if (stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) return cannotWrite(path, "it is a folder");
    if (!S_ISREG(st.st_mode)) {
      if (access(path.c_str(), W_OK) != 0) return cannotWrite(path, std::strerror(errno));
      return std::nullopt;
    }
  }
  const std::string folder = folderOf(path);
  if (stat(folder.c_str(), &st) != 0) return cannotWrite(path, "folder '" + folder + "' does not exist");
  if (!S_ISDIR(st.st_mode)) return cannotWrite(path, "'" + folder + "' is not a folder");
  if (access(folder.c_str(), W_OK | X_OK) != 0) return cannotWrite(path, std::strerror(errno));
  return std::nullopt;
}

OutputSet::~OutputSet() {
  for (const Pending& p : staged_)
    if (!p.temp.empty()) std::remove(p.temp.c_str());
}

std::optional<std::string> OutputSet::addInput(const std::string& path) {
  if (path.empty()) return std::nullopt;
  for (const std::string& out : paths_)
    if (sameFile(path, out)) return "'" + out + "' is both an input and an output (the same file)";
  inputs_.push_back(path);
  return std::nullopt;
}

std::optional<std::string> OutputSet::add(const std::string& path) {
  if (path.empty()) return std::nullopt;
  if (auto err = checkOutputPath(path)) return err;
  for (const std::string& in : inputs_)
    if (sameFile(path, in)) return "'" + path + "' is both an input and an output (the same file)";
  const std::string folder = folderOf(path);
  if (std::find(cleaned_.begin(), cleaned_.end(), folder) == cleaned_.end()) {
    removeStaleTemps(folder);
    cleaned_.push_back(folder);
  }
  std::error_code ec;
  const std::string canonical = fs::weakly_canonical(path, ec).string();
  if (auto other = canonical_.find(canonical); other != canonical_.end() && !isSpecial(path))
    return "two outputs name the same file '" + path + "'" +
           (other->second != path ? " ('" + other->second + "')" : "");
  canonical_.emplace(canonical, path);
  paths_.push_back(path);
  return std::nullopt;
}

std::optional<std::string> OutputSet::stage(const std::string& path, const FileWriter& write) {
  if (isSpecial(path)) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f || !writeAndClose(f, write, false)) return cannotWrite(path, std::strerror(errno));
    staged_.push_back({path, ""});
    return std::nullopt;
  }
  std::string temp;
  const int fd = makeTemp(path, temp);
  if (fd < 0) return cannotWrite(path, std::strerror(errno));
  staged_.push_back({path, temp});
  std::FILE* f = fdopen(fd, "wb");
  if (!f) {
    const int saved = errno;
    close(fd);
    return cannotWrite(path, std::strerror(saved));
  }
  if (!writeAndClose(f, write, true)) return cannotWrite(path, std::strerror(errno));
  return std::nullopt;
}

std::optional<std::string> OutputSet::stage(const std::string& path, const std::string& bytes) {
  return stage(path, [&](std::FILE* f) { return std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size(); });
}

std::optional<std::string> OutputSet::stageAt(const std::string& path, const PathWriter& write) {
  if (isSpecial(path)) {
    if (auto why = write(path)) return cannotWrite(path, *why);
    staged_.push_back({path, ""});
    return std::nullopt;
  }
  std::string temp;
  const int fd = makeTemp(path, temp);
  if (fd < 0) return cannotWrite(path, std::strerror(errno));
  close(fd);
  staged_.push_back({path, temp});
  std::optional<std::string> why = write(temp);
  if (!why) {
    // Flushed to the disk before the rename, as stage() does.
    const int synced = open(temp.c_str(), O_RDONLY | O_CLOEXEC);
    if (synced < 0 || (fsync(synced) != 0 && errno != EINVAL)) why = std::strerror(errno);
    if (synced >= 0) close(synced);
  }
  if (why) {
    std::remove(temp.c_str());
    staged_.back().temp.clear();
    return cannotWrite(path, *why);
  }
  return std::nullopt;
}

std::optional<std::string> OutputSet::commit() {
  for (Pending& p : staged_) {
    if (p.temp.empty()) continue;
    if (std::rename(p.temp.c_str(), p.path.c_str()) != 0) return cannotWrite(p.path, std::strerror(errno));
    p.temp.clear();
  }
  staged_.clear();
  return std::nullopt;
}

std::optional<std::string> writeFileAtomically(const std::string& path, const FileWriter& write) {
  OutputSet out;
  if (auto err = out.add(path)) return err;
  if (auto err = out.stage(path, write)) return err;
  return out.commit();
}

std::optional<std::string> writeFileAtomically(const std::string& path, const std::string& bytes) {
  return writeFileAtomically(
      path, [&](std::FILE* f) { return std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size(); });
}

void ignoreFileSizeSignal() { std::signal(SIGXFSZ, SIG_IGN); }

} // namespace tender
