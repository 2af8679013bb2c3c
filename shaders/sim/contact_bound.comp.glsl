#version 460
// Contact (contact.glsl): each particle's step bound (stepBound; unbounded when free) and its push
// (contactAverage); the particles in contact counted.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint i = threadIndex();
  if (i < p.count) contactBound(i, p.substep);
}
