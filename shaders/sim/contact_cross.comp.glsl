#version 460
// Contact (contact.glsl): the triangles crossingChecked names, against every triangle whose box meets
// theirs; those that cross are flagged.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint t = threadIndex();
  if (t >= p.count || t >= counters.triangle_count || contactGoneWrong()) return;
  uvec4 tri = triangles[t];
  bool was_free =
      ((contact_particles[tri.x].state.y | contact_particles[tri.y].state.y | contact_particles[tri.z].state.y) & 2u) !=
      0u;
  bool all = p.substep == 0u && (u.contact_check.x & SIM_CONTACT_CHECK_ALL) != 0u;
  if (!crossingChecked(all, tri.xyz, u.contact_check.y, u.contact_check.z, was_free)) return;
  vec3 lo, hi;
  contactBox(t, lo, hi);
  contactVisit(CONTACT_VISIT_CROSSING, t, lo, hi);
}
