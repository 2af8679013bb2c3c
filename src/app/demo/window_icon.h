#pragma once
/// The window icon, drawn in code: a sheet of paper with a folded corner and a few printed lines.
#include <cstdint>
#include <vector>

namespace tender::demo {

/// RGBA8 pixels of a size x size icon.
std::vector<uint8_t> drawPaperIcon(int size);

} // namespace tender::demo
