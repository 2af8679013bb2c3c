#pragma once
/// Output files written safely: every path is checked before a run starts, every file is written
/// to a temporary file beside it, flushed and closed with every error checked, then renamed over
/// the target, so a reader sees the old file or the whole new one, never a fragment. A failed
/// write leaves any earlier file untouched. Paths that are not regular files (/dev/stdout, a pipe)
/// are written in place, with the same checks.
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace tender {

/// Writes a file's bytes to an open stream; returns false on failure (errno set).
using FileWriter = std::function<bool(std::FILE*)>;
/// Writes a whole file at the path it is given (through another program); returns why it failed.
using PathWriter = std::function<std::optional<std::string>(const std::string& path)>;

/// Checks that `path` can be written: its folder exists and is writable, and it is not a folder.
/// Returns "cannot write '<path>': <why>" on failure.
std::optional<std::string> checkOutputPath(const std::string& path);

/// A set of output files committed together: stage() writes each to a temporary file, commit()
/// renames them all into place; files staged but not committed are removed. A temporary file is
/// named `.NAME.tmp.HOST-PID.XXXXXX`: the first output added in a folder removes the temporary
/// files there that a process of this host which no longer runs left behind (killed mid-write).
class OutputSet {
public:
  OutputSet() = default;
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// Registers an output before the run: checks the path (checkOutputPath) and that no other
  /// output of the set names the same file. An empty path is ignored.
  std::optional<std::string> add(const std::string& path);
  /// Registers an input the run reads (an empty path is ignored): no output of the set may be the
  /// same file, so that a run never replaces what it reads.
  std::optional<std::string> addInput(const std::string& path);
  /// Writes one registered output to its temporary file; returns the error on failure.
  std::optional<std::string> stage(const std::string& path, const FileWriter& write);
  /// As stage(), with the bytes given.
  std::optional<std::string> stage(const std::string& path, const std::string& bytes);
  /// As stage(), for a writer that opens the file itself: `write` gets the temporary path (the
  /// target itself when that is a device or a pipe); on failure the temporary file is removed and
  /// "cannot write '<path>': <why>" returned.
  std::optional<std::string> stageAt(const std::string& path, const PathWriter& write);
  /// Renames every staged file into place; returns the first error.
  std::optional<std::string> commit();

private:
  struct Pending {
    std::string path, temp;
  };
  std::vector<std::string> paths_, inputs_;
  std::map<std::string, std::string> canonical_; ///< each output's canonical path: the path as added
  std::vector<std::string> cleaned_;             ///< folders whose stale temporary files are removed
  std::vector<Pending> staged_;
};

/// Writes one file atomically (an OutputSet of one); returns the error on failure.
std::optional<std::string> writeFileAtomically(const std::string& path, const FileWriter& write);
/// As writeFileAtomically(), with the bytes given.
std::optional<std::string> writeFileAtomically(const std::string& path, const std::string& bytes);

/// Makes write errors on a file beyond the size limit (ulimit -f) ordinary I/O errors (EFBIG)
/// instead of a signal that kills the process.
void ignoreFileSizeSignal();

} // namespace tender
