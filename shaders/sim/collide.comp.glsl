#version 460
// Gathers repulsion from non-adjacent neighbours in the 27 surrounding cells (Jacobi: writes
// delta only). Cells, and particles within a cell, are visited in the CPU reference's order.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_COLLIDE
#include "sim_common.glsl"
layout(push_constant) uniform PushBlock { SimPush p; };

bool adjacent(uint i, uint j) {
  uint lo = adj_offsets[i], hi = adj_offsets[i + 1u];
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    uint v = adj_list[mid];
    if (v == j) return true;
    if (v < j)
      lo = mid + 1u;
    else
      hi = mid;
  }
  return false;
}

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  float r = u.collision_radius;
  float r2 = r * r;
  vec3 pi = vec3(pos[i]);
  ivec3 ci = cellOf(pi, u.inv_cell);
  vec3 sum = vec3(0.0f);
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        ivec3 c = ci + ivec3(dx, dy, dz);
        uint h = hashCell(c, u.hash_mask);
        uint end = cell_start[h + 1u];
        for (uint k = cell_start[h]; k < end; ++k) {
          uint j = cell_particles[k];
          vec3 pj = vec3(cell_pos[k]);
          vec3 d = pi - pj;
          if (j == i || dot(d, d) >= r2) continue;
          // Count j once, from its own cell, and never repel connected particles.
          if (cellOf(pj, u.inv_cell) != c) continue;
          if (adjacent(i, j)) continue;
          sum += repulsion(pi, pj, r, u.collision_stiffness);
        }
      }
  delta[i] = vec4(sum, 0.0f);
}
