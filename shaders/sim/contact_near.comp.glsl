#version 460
// Contact (contact.glsl), in a substep that builds the grid: each particle against the triangles near
// it, then each live edge against the edges near it, through the grid when the lists are built or
// theirs overflowed: the pairs closer than the contact radius lower the bounds and push.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k < p.count) contactNear(k, NEAR_SEARCH);
}
