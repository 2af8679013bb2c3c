#version 460
// Collision candidate lists, after candidates_check (one invocation): the indirect arguments of the
// hash passes of this substep, their full grids, or none when the lists stand in for the hash.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE 1
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"

void main() {
  bool skip = collideModeNow() == SIM_COLLIDE_CANDIDATES;
  for (uint k = 0u; k < p.count; ++k) hash_args[k] = skip ? uvec4(0u, 1u, 1u, 0u) : hash_args[SIM_HASH_DISPATCHES + k];
#ifdef SIM_BATCH_PASS
  // A fleet: the batch's hash passes of this substep run when a sheet needs them
  if (!skip)
    for (uint k = 0u; k < p.count; ++k) batchArmArgs(SIM_BATCH_ARGS_LIVE_HASH + p.substep * SIM_HASH_DISPATCHES + k, k);
#endif
}
