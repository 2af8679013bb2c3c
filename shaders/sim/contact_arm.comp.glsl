#version 460
// Contact (contact.glsl), after contact_clear (one invocation): the indirect arguments of the grid's
// passes in this substep, none unless it builds the grid.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  if (threadIndex() == 0u) contactArm();
}
