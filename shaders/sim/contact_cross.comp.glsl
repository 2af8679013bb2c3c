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
  if (t < p.count) contactCross(t, p.substep);
}
