#version 460
// Collision candidate lists, before a substep's collision passes: flags (Counters.candidate_flags.x)
// when a particle has travelled SIM_CANDIDATE_TRAVEL x skin or more since the lists were built, so
// that the hash passes and collide pick the substep's mode (collideModeNow) alike.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count || !candidatesCurrentNow(counters.candidate_state)) return;
  if (travelledTooFar(vec3(pos[i]), vec3(candidate_base[i]), candidateSkinNow()))
    atomicOr(counters.candidate_flags.x, 1u);
}
