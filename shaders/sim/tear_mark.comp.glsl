#version 460
// Marks live constraints stretched beyond the tear threshold. The first mark of a substep arms
// the indirect dispatch of the compaction passes (otherwise they run zero workgroups).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_TEAR
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint k = threadIndex();
  if (k >= p.count || !tearingOn(u.tear_factor)) return;
  // Slots past a colour's live count hold stale copies of constraints of that colour, each either
  // torn already (skipped here) or a copy of a live one (same ends, same verdict): the torn set
  // is the same as marking the live ranges only, without looking the ranges up.
  Constraint c = constraints[k];
  if (torn[c.kind_id >> SIM_KIND_BITS] != 0u) return;
  if (markTear(c, pos[c.a], pos[c.b])) {
    uint groups = (compactSlots() + SIM_WG_TEAR - 1u) / SIM_WG_TEAR;
    counters.compact_dispatch = uvec4(groupGrid(groups), 1u, 0u);
#ifdef SIM_BATCH_PASS
    // A fleet: the batch's compaction of this substep runs
    batchArmArgs(SIM_BATCH_ARGS_LIVE_COMPACT + p.substep, SIM_BATCH_ARGS_FULL_COMPACT);
#endif
  }
}
