#version 460
// Projects the live distance constraints of one colour (no two share a particle, so no races) in
// iteration p.first of the substep; project_hinge takes the hinge colours.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PROJECT
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint k = colourSlot(p.color, threadIndex());
  if (k != SIM_NONE) projectDistance(constraints[k]);
}
