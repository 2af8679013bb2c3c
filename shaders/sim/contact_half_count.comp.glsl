#version 460
// The settle stage (contact.glsl, settle_bodies.h): each query's pairs from where the particles
// started the substep, the half-spaces they set each particle's step in counted by particle.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = namedQuery(threadIndex()); // the queries with pairs (armed as Grid::Named's)
  if (k != SIM_NONE && contactChecks().sweeps > 0u && settleStarts()) contactNear(k, NEAR_HALF_COUNT);
}
