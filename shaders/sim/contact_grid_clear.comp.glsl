#version 460
// Contact (contact.glsl): clears the grid's buckets when the grid is built this substep.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k < p.count) contactGridClear(k);
}
