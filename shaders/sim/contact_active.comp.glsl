#version 460
// Contact (contact.glsl), in a substep that builds the grid: each query's flag, 1 when it walks its
// list (contact_walk), scanned next.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k < p.count) contactActiveFlag(k, p.first);
}
