#version 460
// Contact (contact.glsl), after contact_excess: each query's pairs again, each step less its
// excess's mean cut to the share that keeps its pairs' half-spaces (slidePair).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = namedQuery(threadIndex()); // the queries with pairs (Grid::Named)
  if (k != SIM_NONE) contactNear(k, NEAR_SHARE);
}
