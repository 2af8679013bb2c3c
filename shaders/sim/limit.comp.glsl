#version 460
// The stretch limit of a substep: one workgroup a sheet walks the rings around its root
// (limitRoot), a barrier after each, so every particle is placed after its parents
// (limitParticle).
// Workgroup size (sim_common.glsl declares it)
#define SIM_LOCAL_SIZE SIM_WG_LIMIT
// Invocations read the particles other invocations placed in the ring before
#define SIM_COHERENT coherent
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  if (!(u.limit.x > 0.0f)) return; // the same branch for the whole workgroup
  uint root = limitRoot(u.grab_index, u.cols, u.rows), slots = limitSlots(u.cols, u.rows);
  uint rings = limitRings(root, u.cols, u.rows);
  for (uint k = 1u; k <= rings; ++k) {
    for (uint t = gl_LocalInvocationID.x; t < slots; t += gl_WorkGroupSize.x) {
      uint i = ringParticle(root, k, t, u.cols, u.rows);
      if (i != SIM_NONE) limitParticle(i, root);
    }
    memoryBarrierBuffer();
    barrier();
  }
}
