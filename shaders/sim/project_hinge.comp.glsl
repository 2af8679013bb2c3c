#version 460
// Projects the live hinges of one colour (no two share a particle, so no races) in iteration
// p.first of the substep (the first: projectsInIteration); project takes the distance colours.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PROJECT
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint k = colourSlot(p.color, threadIndex());
  if (k == SIM_NONE) return;
  Constraint c = constraints[k]; // read whole (SpirvRules: a fleet's kernels read by address)
  if (projectsInIteration(c.kind_id, p.first)) projectHingeConstraint(c);
}
