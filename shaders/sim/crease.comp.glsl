#version 460
// The creases of a substep: once the sheet has moved (after the floor, contact's cut and the settle), each
// hinge bent past its yield moves its rest angle (creaseHinge).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PROJECT
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint k = threadIndex();
  if (k >= p.count) return;
  creaseHinge(k);
}
