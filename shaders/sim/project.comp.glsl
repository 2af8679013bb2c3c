#version 460
// Projects the live constraints of one colour (no two share a particle, so no races).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PROJECT
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"

void main() {
  uint t = threadIndex();
  uvec2 range = color_range[p.color];
  if (t >= range.y) return; // beyond the live count of this colour
  Constraint c = constraints[range.x + t];
  vec4 pa = pos[c.a], pb = pos[c.b]; // a != b: each end is read once
  PairDelta d = solveDistance(pa, pb, c.rest, u.stiffness[c.kind_id & SIM_KIND_MASK]);
  pos[c.a] = pa + vec4(d.da, 0.0f);
  pos[c.b] = pb + vec4(d.db, 0.0f);
}
