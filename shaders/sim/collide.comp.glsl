#version 460
// Gathers repulsion from non-adjacent neighbours (Jacobi: writes delta only): from the candidate
// lists, or from the surrounding cells of the hash, which may rebuild the lists (collideModeNow).
// Cells, and particles within a cell, are summed in the CPU reference's order.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_COLLIDE
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  uint mode = collideModeNow();
  vec3 pi = vec3(pos[i]);
  bool fits = true;
  vec3 repel = mode == SIM_COLLIDE_CANDIDATES ? candidateRepulsion(i, pi) : gatherParticle(i, pi, mode, fits);
  if (!fits) atomicOr(counters.candidate_flags.y, 1u);
  delta[i] = vec4(repel, 0.0f);
}
