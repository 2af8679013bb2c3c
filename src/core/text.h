#pragma once
/// Text from outside (a path, a key, a preset's name) made fit for a message of one line.
#include <string>

namespace tender {

/// `text` with every control character, DEL and byte that is not UTF-8 written as an escape (\n,
/// \t, \xNN), so that it prints as one line of text whatever it held (a NUL included).
std::string printable(const std::string& text);

} // namespace tender
