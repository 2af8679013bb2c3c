#version 460
// Spatial hash, step 4: orders each bucket by particle index, positions alongside.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  hashSort(i, vec3(pos[i]));
}
