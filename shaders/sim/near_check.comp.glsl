#version 460
// Collision candidate lists, before a substep's collision passes: flags (Counters.near_flags.x)
// when a particle has travelled SIM_NEAR_TRAVEL x skin or more since the lists were built, so
// that the hash passes and collide pick the substep's mode (nearModeNow) alike.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#include "sim_common.glsl"
layout(push_constant) uniform PushBlock { SimPush p; };

void main() {
  uint i = threadIndex();
  if (i >= p.count || !nearListsCurrent(counters.near)) return;
  if (travelledTooFar(vec3(pos[i]), vec3(near_base[i]), nearSkin())) atomicOr(counters.near_flags.x, 1u);
}
