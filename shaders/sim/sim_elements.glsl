// Per-element bodies of the simulation passes, shared by the one-pass-per-dispatch shaders and
// the fused small-sheet tick (which runs them in one workgroup, positions in shared memory).
// Include after sim_common.glsl.
#ifndef SIM_ELEMENTS_GLSL
#define SIM_ELEMENTS_GLSL

// The bodies the CPU reference runs too; SIM_POSITION(j), the position of particle j as the bodies
// read it (pos[j], or the fused tick's shared memory)
#include "sim_bodies.h"

// Spatial hash, step 1: the bucket of particle i (at p) and one more particle in that bucket.
void hashCount(uint i, vec3 p) {
  uint h = hashCell(cellOf(p, u.inv_cell), u.hash_mask);
  particle_cell[i] = h;
  atomicAdd(cell_count[h], 1u);
}

// Spatial hash, step 3: particle i takes a slot of its bucket. The count is used as a
// down-counter, so every count is back at zero for the next rebuild.
void hashScatter(uint i) {
  uint h = particle_cell[i];
  uint slot = atomicAdd(cell_count[h], 0xFFFFFFFFu) - 1u;
  cell_scatter[cell_start[h] + slot] = i;
}

// Grid column and row of particle j (index = row * cols + col); the float quotient is off by at
// most one row, which the remainder corrects.
ivec2 gridOf(uint j, float inv_cols) {
  int row = int((float(j) + 0.5f) * inv_cols);
  int col = int(j) - row * int(u.cols);
  if (col < 0) return ivec2(col + int(u.cols), row - 1);
  if (col >= int(u.cols)) return ivec2(col - int(u.cols), row + 1);
  return ivec2(col, row);
}

// Grid place (column, row) of a particle packed in one word: row << 16 | column (sides < 2^16).
uint packGrid(ivec2 g) { return uint(g.y) << 16u | uint(g.x); }
ivec2 unpackGrid(uint g) { return ivec2(int(g & 0xFFFFu), int(g >> 16u)); }

// Spatial hash, step 4: particle i (at p) goes to its place in its bucket ordered by particle
// index: the number of bucket entries with a smaller index (ranks are unique, so no races). The
// position and the packed grid place go along, so the collision gather reads buckets as one
// contiguous array and tests adjacency without dividing by the row length.
void hashSort(uint i, vec3 p) {
  uint h = particle_cell[i];
  uint first = cell_start[h], end = cell_start[h + 1u];
  uint rank = 0u;
  for (uint k = first; k < end; ++k) rank += cell_scatter[k] < i ? 1u : 0u;
  cell_particles[first + rank] = i;
  cell_pos[first + rank] = uvec4(floatBitsToUint(p), packGrid(gridOf(i, simDiv(1.0f, float(u.cols)))));
}

// True when particles i and j share a constraint (binary search in i's sorted adjacency list).
bool adjacentInList(uint i, uint j) {
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

// Whether particles i (grid place gi, adjacency mask mask_i) and j share a constraint, from the
// mask alone: SIM_CONNECTED, SIM_UNCONNECTED, or SIM_ASK_LIST when j is outside i's stencil and i
// has farther neighbours (search the adjacency list).
#define SIM_UNCONNECTED 0u
#define SIM_CONNECTED 1u
#define SIM_ASK_LIST 2u
uint adjacencyOf(ivec2 gi, uint mask_i, uint grid_j) {
  ivec2 off = unpackGrid(grid_j) - gi;
  if (all(lessThanEqual(abs(off), ivec2(SIM_ADJ_STENCIL)))) {
    uint bit = uint((off.y + SIM_ADJ_STENCIL) * (2 * SIM_ADJ_STENCIL + 1) + off.x + SIM_ADJ_STENCIL);
    return (mask_i >> bit) & 1u;
  }
  return (mask_i & SIM_ADJ_FAR) != 0u ? SIM_ASK_LIST : SIM_UNCONNECTED;
}

// Neighbour cells (bit dz*9 + dy*3 + dx, offsets + 1) with offset -1, 0, +1 on the x, y and z axes.
const uint kCellsWithOffset[9] = uint[9](0x1249249u, 0x2492492u, 0x4924924u,  // x
                                         0x01C0E07u, 0x0E07038u, 0x70381C0u,  // y
                                         0x00001FFu, 0x003FE00u, 0x7FC0000u); // z

// Repulsion gathered by particle i at pi from the non-adjacent particles closer than the collision
// radius, in the 27 cells around it (Jacobi: reads bucket-ordered positions only). Cells, and
// particles within a cell, are summed in the CPU reference's order. A neighbour cell on one side
// can hold a particle within `search` only when pi is closer than that to that side of its own
// cell (`search`, at least the radius, never exceeds a cell); the test is in cell units with a
// margin, so the cells skipped add no term and the sum is unchanged. Unless `list` is SIM_NONE,
// the particles not connected to i closer than `search` also go to the candidate list record at
// candidates[list] (ascending); `fits` is false when they are more than SIM_CANDIDATE_CAPACITY.
vec3 gatherRepulsion(uint i, vec3 pi, float search, uint list, out bool fits) {
  float r = u.collision_radius;
  float r2 = r * r, search2 = search * search;
  ivec3 ci = cellOf(pi, u.inv_cell);
  vec3 scaled = pi * u.inv_cell;
  float reach = search * u.inv_cell + 1e-3f;
  ivec2 gi = gridOf(i, simDiv(1.0f, float(u.cols)));
  uint grid_i = packGrid(gi);
  uint mask_i = adj_mask[i];
  uint visit = 0x7FFFFFFu;
  for (int a = 0; a < 3; ++a) {
    float f = scaled[a] - float(ci[a]);
    bool sure = abs(scaled[a]) < 1024.0f && f >= 0.0f && f <= 1.0f; // rounding well inside the margin
    uint sides = kCellsWithOffset[3 * a + 1];
    if (!sure || !(f >= reach)) sides |= kCellsWithOffset[3 * a];
    if (!sure || !(1.0f - f >= reach)) sides |= kCellsWithOffset[3 * a + 2];
    visit &= sides;
  }
  // Each bucket is read in windows of 32 slots: a tight loop finds the slots within `search`
  // that may repel (a bit each: not i, not a connected grid neighbour), then a second loop
  // visits those few in order. Kept apart, SIMD lanes do not step through the rest of the tests
  // and the repulsion for every candidate.
  vec3 sum = vec3(0.0f);
  uint listed = 0u;
  while (visit != 0u) {
    int b = findLSB(visit); // ascending: dz, dy, dx order
    visit &= visit - 1u;
    ivec3 c = ci + ivec3(b % 3 - 1, b / 3 % 3 - 1, b / 9 - 1);
    uint h = hashCell(c, u.hash_mask);
    uint end = cell_start[h + 1u];
    for (uint first = cell_start[h]; first < end; first += 32u) {
      uint close = 0u;
      for (uint k = first; k < min(first + 32u, end); ++k) {
        uvec4 q = cell_pos[k];
        vec3 d = pi - uintBitsToFloat(q.xyz);
        bool may_repel = q.w != grid_i && adjacencyOf(gi, mask_i, q.w) != SIM_CONNECTED;
        close |= dot3(d, d) < search2 && may_repel ? 1u << (k - first) : 0u;
      }
      for (; close != 0u; close &= close - 1u) {
        uvec4 q = cell_pos[first + uint(findLSB(close))];
        vec3 pj = uintBitsToFloat(q.xyz);
        // Count j once, from its own cell
        if (cellOf(pj, u.inv_cell) != c) continue;
        ivec2 gj = unpackGrid(q.w);
        uint j = uint(gj.y) * u.cols + uint(gj.x);
        if (adjacencyOf(gi, mask_i, q.w) == SIM_ASK_LIST && adjacentInList(i, j)) continue;
        if (list != SIM_NONE) {
          // Insertion into the ascending list
          if (listed < SIM_CANDIDATE_CAPACITY) {
            uint e = listed + 1u;
            for (; e > 1u && candidates[list + e - 1u] > j; --e) candidates[list + e] = candidates[list + e - 1u];
            candidates[list + e] = j;
          }
          ++listed;
        }
        vec3 d = pi - pj;
        if (dot3(d, d) < r2) sum += repulsion(pi, pj, r, u.collision_stiffness);
      }
    }
  }
  fits = listed <= SIM_CANDIDATE_CAPACITY;
  if (list != SIM_NONE) candidates[list] = fits ? listed : 0u;
  return sum;
}

// Repulsion on particle i at pi from its candidate list (lists in use; positions by
// SIM_POSITION, none moved yet this substep): the candidates closer than the radius, summed as
// gatherRepulsion sums them, by neighbour cell (cellCode) and then by index (the list is
// ascending), so the result is the gather's to the bit.
vec3 candidateRepulsion(uint i, vec3 pi) {
  uint list = i * SIM_CANDIDATE_STRIDE, count = candidates[list];
  float r = u.collision_radius, r2 = r * r;
  ivec3 ci = cellOf(pi, u.inv_cell);
  uint codes = 0u; // neighbour cells holding a candidate within the radius
  for (uint e = 1u; e <= count; ++e) {
    vec3 pj = vec3(SIM_POSITION(candidates[list + e]));
    vec3 d = pi - pj;
    ivec3 o = cellOf(pj, u.inv_cell) - ci;
    if (dot3(d, d) < r2 && all(lessThanEqual(abs(o), ivec3(1)))) codes |= 1u << cellCode(o);
  }
  vec3 sum = vec3(0.0f);
  for (; codes != 0u; codes &= codes - 1u) {
    uint b = uint(findLSB(codes));
    for (uint e = 1u; e <= count; ++e) {
      vec3 pj = vec3(SIM_POSITION(candidates[list + e]));
      vec3 d = pi - pj;
      ivec3 o = cellOf(pj, u.inv_cell) - ci;
      if (dot3(d, d) < r2 && all(lessThanEqual(abs(o), ivec3(1))) && cellCode(o) == b)
        sum += repulsion(pi, pj, r, u.collision_stiffness);
    }
  }
  return sum;
}

// Collision of particle i at pi in a substep of `mode` (SIM_CANDIDATE_*, not SIM_COLLIDE_CANDIDATES: the
// lists read other particles, which must not have moved): its repulsion gathered from the hash; in
// SIM_COLLIDE_BUILD also its candidate list and the position it was built at. False in `fits` when
// the list overflowed.
vec3 gatherParticle(uint i, vec3 pi, uint mode, out bool fits) {
  if (mode != SIM_COLLIDE_BUILD) return gatherRepulsion(i, pi, u.collision_radius, SIM_NONE, fits);
  candidate_base[i] = vec4(pi, 0.0f);
  return gatherRepulsion(i, pi, candidateSearchNow(), i * SIM_CANDIDATE_STRIDE, fits);
}

// Tear compaction, step 1: the keep flag of compaction slot k (a constraint slot or a triangle)
// and a copy of the element to compact from. The scan of the flags gives every survivor its place.
void tearFlags(uint k) {
  uint m = u.constraint_count;
  uint keep = 0u;
  if (k < m) {
    uvec2 range = color_range[colorOf(k)];
    Constraint c = constraints[k];
    keep = (k < range.x + range.y && torn[c.kind_id >> SIM_KIND_BITS] == 0u) ? 1u : 0u;
    compact_tmp[k] = uvec4(c.a, c.b, floatBitsToUint(c.rest), c.kind_id);
  } else if (k < m + u.triangle_count) {
    uint t = k - m;
    if (t < counters.triangle_count) {
      uvec4 tri = triangles[t];
      uvec2 e = tri_edges[tri.w];
      keep = (torn[e.x] == 0u && torn[e.y] == 0u) ? 1u : 0u;
      compact_tmp[k] = tri;
    }
  }
  scratch[k] = keep;
}

// Tear compaction, step 3: survivors move to their scanned place (stable, each colour range keeps
// its first slot); the colour counts and the triangle count shrink.
void tearCompact(uint k) {
  uint m = u.constraint_count;
  if (k < m) {
    if (scratch[k + 1u] != scratch[k]) {
      uint first = color_range[colorOf(k)].x;
      uvec4 c = compact_tmp[k];
      constraints[first + scratch[k] - scratch[first]] = Constraint(c.x, c.y, uintBitsToFloat(c.z), c.w);
    }
  } else if (k < m + u.triangle_count) {
    if (scratch[k + 1u] != scratch[k]) triangles[scratch[k] - scratch[m]] = compact_tmp[k];
  }
  if (k < u.color_count) {
    uvec2 range = color_range[k];
    color_range[k].y = scratch[range.x + range.y] - scratch[range.x];
  }
  if (k == 0u) {
    // At most the sheet's triangles, whatever the scan held: the renderer draws this many, and a
    // count gone wrong must not make a draw of billions of vertices
    uint live = min(scratch[m + counters.triangle_count] - scratch[m], u.triangle_count);
    counters.triangle_count = live;
    counters.draw_args.x = 3u * live;
  }
}

// Ring k of the stretch limit from `roots` (limitRootSet; limitParticle), slots `first`, first +
// `stride`, ... of it around each root, each particle around its own (limitRootOf): a workgroup's
// invocations share a ring, and a barrier follows it (limit.comp, the fused tick).
void limitRing(uvec4 roots, uint k, uint first, uint stride) {
  uint slots = limitSlots(u.cols, u.rows);
  uvec4 rx = roots % u.cols, ry = roots / u.cols;
  for (uint j = 0u; j < roots.w; ++j) {
    uint root = roots[j];
    for (uint t = first; t < slots; t += stride) {
      uint i = ringParticle(root, k, t, u.cols, u.rows);
      if (i != SIM_NONE && (roots.w == 1u || limitRootAt(i % u.cols, i / u.cols, rx, ry, roots.w) == j))
        limitParticle(i, root);
    }
  }
}

#endif
