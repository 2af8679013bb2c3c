#version 460
// Contact (contact.glsl): clears the grid's header for the substep and says whether the pair lists are
// built again (one invocation).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  if (threadIndex() != 0u) return;
  contactBegin(p.substep, true);
#ifndef SIM_BATCH_PASS
  disarmSettle(); // a fleet's host writes the batch's live arguments disarmed
#endif
}
