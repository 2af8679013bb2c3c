#version 460
// Nearest particle to a ray within a radius, in three steps (specialization constant `step`):
// 0: smallest squared distance; 1: smallest index at that distance; 2: that particle's ray t and
// position (so a grab costs one round trip).
// Squared distances are >= 0, so their float bits order like the floats (atomicMin on uint).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE PickPush
#include "sim_common.glsl"
layout(constant_id = 0) const uint kStep = 0u;

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  vec2 r = rayPointDistance2(vec3(p.origin_radius), vec3(p.dir), vec3(pos[i]));
  float radius = p.origin_radius.w;
  if (!(r.x <= radius * radius)) return;
  if (kStep == 0u) {
    atomicMin(pick.d2, floatBitsToUint(r.x));
  } else if (kStep == 1u) {
    if (floatBitsToUint(r.x) == pick.d2) atomicMin(pick.index, i);
  } else if (i == pick.index) {
    pick.t = r.y;
    pick.pos = pos[i];
  }
}
