#version 460
// Contact (contact.glsl): the particles of the triangles that cross another go free this substep.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint t = threadIndex();
  if (t >= p.count || t >= counters.triangle_count || contact_grid[SIM_CONTACT_HEADER + t] == 0u) return;
  uvec4 tri = triangles[t];
  atomicOr(contact_particles[tri.x].state.y, 1u);
  atomicOr(contact_particles[tri.y].state.y, 1u);
  atomicOr(contact_particles[tri.z].state.y, 1u);
}
