#version 460
// Tear compaction, step 1 (indirect): a keep flag per constraint slot and per triangle, and a
// copy of each element to compact from. The scan of the flags gives every survivor its place.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_TEAR
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  uint m = u.constraint_count;
  if (k >= compactSlots()) return;
  uint keep = 0u;
  if (k < m) {
    uvec2 range = color_range[colorOf(k)];
    Constraint c = constraints[k];
    keep = (k < range.x + range.y && torn[c.kind_id >> SIM_KIND_BITS] == 0u) ? 1u : 0u;
    compact_tmp[k] = uvec4(c.a, c.b, floatBitsToUint(c.rest), c.kind_id);
  } else if (k < m + u.triangle_count) {
    uint t = k - m;
    if (t < counters.triangle_count) {
      uvec4 tri = triangles[t];
      uvec2 e = tri_edges[tri.w];
      keep = (torn[e.x] == 0u && torn[e.y] == 0u) ? 1u : 0u;
      compact_tmp[k] = tri;
    }
  }
  scratch[k] = keep;
}
