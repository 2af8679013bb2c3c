#version 460
// The settle stage (contact.glsl, settle_bodies.h), after the counts' scan: each query's pairs
// again, their half-spaces put in each particle's list (in any order: the settle takes their
// minimum room).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = namedQuery(threadIndex()); // the queries with pairs (armed as Grid::Named's)
  if (k != SIM_NONE && contactChecks().sweeps > 0u && settleStarts()) contactNear(k, NEAR_HALF_FILL);
}
