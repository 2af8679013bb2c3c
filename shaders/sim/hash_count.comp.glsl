#version 460
// Spatial hash, step 1: the bucket of each particle and the particle count of each bucket.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  hashCount(i, vec3(pos[i]));
}
