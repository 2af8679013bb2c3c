#version 460
// Contact (contact.glsl): each particle's start of the substep; the grid's buckets and the triangles'
// crossing flags cleared; the longest live edge.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k >= p.count) return;
  if (k < u.particle_count) {
    float r = u.contact.x;
    contact_particles[k].start = pos[k];
    // Free in the last substep: bit 1 (crossingChecked looks at its triangles again)
    contact_particles[k].state = uvec4(floatBitsToUint(r * r), (contact_particles[k].state.y & 1u) << 1, 0u, 0u);
    contact_particles[k].sum = ivec4(0);
  }
  uint buckets = 2u * (u.contact_grid.x + 1u); // the triangles' and the edges'
  if (k <= buckets) scratch[contactCounts() + k] = 0u;
  if (k < buckets) scratch[contactFill() + k] = 0u;
  if (k < u.triangle_count) contact_grid[SIM_CONTACT_HEADER + k] = 0u;
  if (k < contactEdgeCount() && contactEdgeLive(k)) {
    vec3 d = vec3(pos[contact_edges[k].y]) - vec3(pos[contact_edges[k].x]);
    atomicMax(contact_grid[CONTACT_LONGEST], floatBitsToUint(dot3(d, d)));
  }
}
