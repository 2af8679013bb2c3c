#version 460
// Contact (contact.glsl): each particle against the triangles near it, then each live edge against the
// edges near it: the pairs closer than the contact radius lower the bounds and push.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k >= p.count || contactGoneWrong()) return;
  // The boxes are widened a little past the radius: which pairs count is their distance's call
  float reach = 1.01f * u.contact.x;
  if (k < u.particle_count) {
    if (contactFree(k)) return;
    vec3 x = vec3(pos[k]);
    contactVisit(CONTACT_VISIT_TRIANGLES, k, x - vec3(reach), x + vec3(reach));
    return;
  }
  uint e = k - u.particle_count;
  if (e >= contactEdgeCount() || !contactEdgeLive(e)) return;
  vec3 a = vec3(pos[contact_edges[e].x]), b = vec3(pos[contact_edges[e].y]);
  contactVisit(CONTACT_VISIT_EDGES, e, min(a, b) - vec3(reach), max(a, b) + vec3(reach));
}
