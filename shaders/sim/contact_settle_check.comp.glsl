#version 460
// The settle stage (contact.glsl, settle_bodies.h) as it starts: whether any structural edge is
// longer than the stretch limit with a free end; without one the stage lists and moves nothing.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k < p.count && contactSettleCheck(k, p.substep)) { // the stage starts: its half-spaces and first sweep
    armSettle(0u);
    armSettle(1u);
  }
}
