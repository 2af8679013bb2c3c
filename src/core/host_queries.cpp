#include "host_queries.h"

namespace tender {

using namespace shaderio;

PickResult pickNearest(const std::vector<glm::vec4>& pos, glm::vec3 o, glm::vec3 d, float radius) {
  PickResult best{};
  best.index = SIM_NONE;
  float best_d2 = radius * radius;
  for (uint32_t i = 0; i < pos.size(); ++i) {
    vec2 r = rayPointDistance2(o, d, vec3(pos[i]));
    if (r.x <= best_d2 && (best.index == SIM_NONE || r.x < best_d2)) {
      best.index = i;
      best.t = r.y;
      best_d2 = r.x;
    }
  }
  if (best.index != SIM_NONE) {
    best.d2 = floatBitsToUint(best_d2);
    best.pos = pos[best.index];
  }
  return best;
}

void gridNormals(const std::vector<glm::vec4>& pos, uint32_t cols, uint32_t rows, std::vector<glm::vec4>& out) {
  const uint32_t W = cols, H = rows;
  out.resize(pos.size());
  for (uint32_t j = 0; j < H; ++j)
    for (uint32_t i = 0; i < W; ++i) {
      const uint32_t l = j * W + (i > 0 ? i - 1 : i), r = j * W + (i + 1 < W ? i + 1 : i);
      const uint32_t up = (j > 0 ? j - 1 : j) * W + i, dn = (j + 1 < H ? j + 1 : j) * W + i;
      out[j * W + i] = vec4(gridNormal(vec3(pos[l]), vec3(pos[r]), vec3(pos[up]), vec3(pos[dn])), 0.0f);
    }
}

} // namespace tender
