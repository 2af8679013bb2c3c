#version 460
// Contact (contact.glsl), after the floor: each query's pairs from where the particles started the
// substep, each step's excess beyond its pairs' half-spaces summed (slidePair).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = namedQuery(threadIndex()); // the queries with pairs (Grid::Named)
  if (k != SIM_NONE) contactNear(k, NEAR_EXCESS);
}
