#version 460
// Tear compaction, step 3 (indirect): survivors move to their scanned place (stable, each colour
// range keeps its first slot); the colour counts and the triangle count shrink.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_TEAR
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  uint m = u.constraint_count;
  if (k >= compactSlots()) return;
  if (k < m) {
    if (scratch[k + 1u] != scratch[k]) {
      uint first = color_range[colorOf(k)].x;
      uvec4 c = compact_tmp[k];
      constraints[first + scratch[k] - scratch[first]] = Constraint(c.x, c.y, uintBitsToFloat(c.z), c.w);
    }
  } else if (k < m + u.triangle_count) {
    if (scratch[k + 1u] != scratch[k]) triangles[scratch[k] - scratch[m]] = compact_tmp[k];
  }
  if (k < u.color_count) {
    uvec2 range = color_range[k];
    color_range[k].y = scratch[range.x + range.y] - scratch[range.x];
  }
  if (k == 0u) {
    uint live = scratch[m + counters.triangle_count] - scratch[m];
    counters.triangle_count = live;
    counters.draw_args.x = 3u * live;
  }
}
