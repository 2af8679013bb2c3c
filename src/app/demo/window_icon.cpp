#include "window_icon.h"

#include <algorithm>
#include <cmath>

namespace tender::demo {

std::vector<uint8_t> drawPaperIcon(int size) {
  std::vector<uint8_t> px(size_t(size) * size * 4, 0);
  const float s = float(size);
  // Sheet rectangle, and the size of the folded corner (top right).
  const float x0 = 0.18f * s, x1 = 0.82f * s, y0 = 0.08f * s, y1 = 0.92f * s, fold = 0.24f * s;
  auto put = [&](int x, int y, uint8_t r, uint8_t g, uint8_t b) {
    uint8_t* p = &px[(size_t(y) * size + size_t(x)) * 4];
    p[0] = r, p[1] = g, p[2] = b, p[3] = 255;
  };
  const float edge = std::max(1.0f, s / 32.0f);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float fx = float(x) + 0.5f, fy = float(y) + 0.5f;
      if (fx < x0 || fx > x1 || fy < y0 || fy > y1) continue;
      // Distance past the fold line x - x1 + fold = y - y0 (the corner is cut away).
      float cut = (fx - (x1 - fold)) - (fy - y0);
      if (cut > 0.0f) continue;
      bool in_flap = fx > x1 - fold && fy < y0 + fold;
      bool border = fx - x0 < edge || x1 - fx < edge || fy - y0 < edge || y1 - fy < edge || -cut < edge;
      if (border)
        put(x, y, 0x55, 0x55, 0x55);
      else if (in_flap)
        put(x, y, 0xd8, 0xd4, 0xd0); // the back of the folded flap
      else
        put(x, y, 0xfa, 0xf9, 0xf5);
    }
  // Printed lines.
  for (int line = 0; line < 5; ++line) {
    int y = int((0.42f + 0.09f * float(line)) * s);
    int xe = int((line == 4 ? 0.5f : 0.72f) * s);
    for (int t = 0; t < std::max(1, size / 24); ++t)
      for (int x = int(0.28f * s); x < xe && y + t < size; ++x) put(x, y + t, 0x70, 0x70, 0x70);
  }
  return px;
}

} // namespace tender::demo
