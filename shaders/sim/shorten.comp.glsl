#version 460
// The shorten stage: the structural edges of one colour (no two share a particle, so no races)
// longer than the stretch limit shortened to it from both ends, in iteration p.first of the
// substep, while nothing holds the sheet (limitShortens).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PROJECT
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  if (!stageRuns(SIM_STAGE_shorten, conditionsNow())) return; // the same branch for every invocation
  uint k = colourSlot(p.color, threadIndex());
  if (k != SIM_NONE) shortenConstraint(constraints[k]);
}
