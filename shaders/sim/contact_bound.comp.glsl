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
  if (i >= p.count) return;
  float r = u.contact.x;
  uint nearest = contactGoneWrong() ? 0u : contact_particles[i].state.x;
  if (nearest < floatBitsToUint(r * r)) atomicAdd(contact_grid[CONTACT_COUNT], 1u);
  contact_particles[i].start.w =
      contactFree(i) ? uintBitsToFloat(0x7F800000u) : stepBound(uintBitsToFloat(nearest), r, u.contact.y);
  contact_particles[i].push = vec4(contactAverage(contact_particles[i].sum, u.contact.w), 0.0f);
}
