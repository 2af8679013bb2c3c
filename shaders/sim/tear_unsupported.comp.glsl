#version 460
// After the tear marks (indirect, zero workgroups unless something tore this substep): marks the
// shear and tri-bend constraints whose triangles are gone, so that torn pieces come apart.
// Slots past a colour's live count are stale copies with the same verdict (see tear_mark).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_TEAR
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint k = threadIndex();
  if (k < u.constraint_count) markUnsupported(constraints[k]);
}
