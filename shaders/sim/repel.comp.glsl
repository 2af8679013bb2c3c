#version 460
// Moves each free particle by the repulsion the collide pass gathered (Jacobi: every delta was
// gathered before any particle moves), ahead of the projection.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  pos[i] = repelParticle(pos[i], vec3(delta[i]), u.flags);
}
