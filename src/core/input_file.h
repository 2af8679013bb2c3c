#pragma once
/// Input files read whole, safely: only a regular file is read (a folder, a FIFO, a device or a
/// socket is refused before it is opened for reading, so a FIFO with no writer never blocks and
/// /dev/zero is never read), and never more than a limit of bytes (a file over it is refused from
/// its size, so a huge sparse file costs nothing; one that grows past it while it is read is
/// refused too).
#include <cstdint>
#include <optional>
#include <string>

namespace tender {

/// Reads the file at `path` into `text`, at most `max_bytes`; returns why it cannot ("it is a
/// folder", "No such file or directory", ...) on failure.
std::optional<std::string> readInputFile(const std::string& path, uint64_t max_bytes, std::string& text);

/// True when `a` and `b` name the same existing file (the same device and inode).
bool sameFile(const std::string& a, const std::string& b);

} // namespace tender
