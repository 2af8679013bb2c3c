#version 460
// The settle stage (settle_bodies.h): in sweep p.first, the structural edges of one colour (no two
// share a particle, so no races) longer than the stretch limit shortened within what the contact
// lets each end's step go; none after a sweep that moved nothing (settleSweeps: its workgroups are
// armed by the sweep before, armSettle).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PROJECT
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  if (p.first >= contactChecks().sweeps || !settleSweeps(p.first)) return; // the same branch for every invocation
  uint k = colourSlot(p.color, threadIndex());
  if (k == SIM_NONE) return;
  if (contactSettle(constraints[k], p.first, p.substep) && p.first + 1u < contactChecks().sweeps)
    armSettle(p.first + 2u); // the next sweep
}
