#version 460
// Contact (contact.glsl), in a substep that builds the grid: the queries that walk their lists named
// in order, and contact_walk's arguments until the next build.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k < p.count) contactEmit(k, p.first);
}
