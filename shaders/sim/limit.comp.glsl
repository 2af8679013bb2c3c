#version 460
// The stretch limit of a substep: one workgroup a sheet walks rings p.first to p.first + p.count - 1
// around its roots (limitRootSet), a barrier after each, so every particle is placed after its parents
// (limitParticle); a large sheet's rings take several dispatches (limitRingsPerDispatch).
// Workgroup size: specialization constant 0, the device's (limitWorkgroup in sim_pipeline.h)
#define SIM_LOCAL_SIZE SIM_WG_LIMIT
#define SIM_LOCAL_SIZE_SPECIALIZED
// Invocations read the particles other invocations placed in the ring before
#define SIM_COHERENT coherent
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  if (!stageRuns(SIM_STAGE_limit, conditionsNow())) return; // the same branch for the whole workgroup
  uvec4 roots = limitRootSet(u.limit_roots, u.grab_index, u.cols, u.rows);
  LimitKeys limit = u.limit; // read whole (limitParticle says why)
  uint last = min(uint(limit.last_ring), p.first + p.count - 1u);
  for (uint k = p.first; k <= last; ++k) {
    limitRing(roots, k, gl_LocalInvocationID.x, gl_WorkGroupSize.x);
    groupMemoryBarrier(); // at the workgroup's scope: no other workgroup reads this sheet's places
    barrier();
  }
}
