// The GPU's penetration-free contact, the contact_* passes of the integrate stage (contact.h has
// the maths and the proof). Every substep a hashed grid of the live triangles' and edges' boxes is
// built (count -> scan -> scatter; cells as wide as the longest edge and the contact diameter, so a
// box spans two cells a side at most), then each particle and each edge looks up the boxes near
// it. A pair is visited once, in the cell of the low corner of the two boxes' overlap, and counts
// when its primitives are closer than the contact radius, exactly as the CPU's lists count it
// (CpuContact): the bounds are atomic minimums of float bits and the pushes integer sums
// (contactFixed), so neither depends on the order of the pairs, and the bits are the CPU's.
#ifndef SIM_CONTACT_GLSL
#define SIM_CONTACT_GLSL
#include "sim_common.glsl"

// Words of the grid's header (SIM_CONTACT_HEADER)
#define CONTACT_LONGEST 0u
#define CONTACT_TANGLED 1u
#define CONTACT_COUNT 2u

// The entries of the grid, after the header and a crossing flag per triangle slot: an entry k is
// live triangle slot k (k < u.triangle_count) or edge k - u.triangle_count
uint contactEntries() { return SIM_CONTACT_HEADER + u.triangle_count; }
uint contactCounts() { return u.contact_grid.y; }
uint contactFill() { return u.contact_grid.z; }
uint contactEdgeCount() { return u.contact_grid.w; }

// True when triangle id `id` is live (its two edge constraints stand, as the compaction keeps it)
bool contactTriangleLive(uint id) {
  return id != SIM_NONE && torn[tri_edges[id].x] == 0u && torn[tri_edges[id].y] == 0u;
}

// True when edge e of SIM_BIND_CONTACT_EDGES belongs to a live triangle
bool contactEdgeLive(uint e) {
  return contactTriangleLive(contact_edges[e].z) || contactTriangleLive(contact_edges[e].w);
}

// The positions went wrong (an edge of no finite length): no pair is looked for and nothing moves,
// as on the CPU
bool contactGoneWrong() { return contact_grid[CONTACT_LONGEST] >= 0x7F800000u; }

// Cells per unit of length: the cells are SIM_CONTACT_CELL_ROOM x the longest live edge or the
// contact diameter, whichever is longer
float contactInvCell() {
  float longest = simSqrt(uintBitsToFloat(contact_grid[CONTACT_LONGEST]));
  return simDiv(1.0f, SIM_CONTACT_CELL_ROOM * max(longest, 2.0f * u.contact.x));
}

// The box of grid entry k (a live triangle slot or a live edge); false when k is neither
bool contactBox(uint k, out vec3 lo, out vec3 hi) {
  if (k < u.triangle_count) {
    if (k >= counters.triangle_count) return false;
    uvec4 t = triangles[k];
    vec3 a = vec3(pos[t.x]), b = vec3(pos[t.y]), c = vec3(pos[t.z]);
    lo = min(a, min(b, c));
    hi = max(a, max(b, c));
    return true;
  }
  uint e = k - u.triangle_count;
  if (e >= contactEdgeCount() || !contactEdgeLive(e)) return false;
  vec3 a = vec3(pos[contact_edges[e].x]), b = vec3(pos[contact_edges[e].y]);
  lo = min(a, b);
  hi = max(a, b);
  return true;
}

// True when the closed boxes [lo, hi] and [elo, ehi] meet
bool boxesMeet(vec3 lo, vec3 hi, vec3 elo, vec3 ehi) {
  return lo.x <= ehi.x && elo.x <= hi.x && lo.y <= ehi.y && elo.y <= hi.y && lo.z <= ehi.z && elo.z <= hi.z;
}

// The bucket of a cell: the triangles' in the first half of the table, the edges' in the second, so
// that a look-up reads only the kind it looks for
uint contactBucket(ivec3 cell, bool edge) {
  return hashCell(cell, u.contact_grid.x) + (edge ? u.contact_grid.x + 1u : 0u);
}

// The buckets of the cells a box of grid entry k spans, each once (two cells of a box may share a
// bucket): counted (scatter false) or filled with k (scatter true)
void contactInsert(uint k, bool scatter) {
  vec3 lo, hi;
  if (contactGoneWrong() || !contactBox(k, lo, hi)) return;
  float inv = contactInvCell();
  ivec3 a = cellOf(lo, inv), b = min(cellOf(hi, inv), a + ivec3(1));
  uint seen[SIM_CONTACT_CELLS_PER_BOX];
  uint count = 0u;
  for (int z = a.z; z <= b.z; ++z)
    for (int y = a.y; y <= b.y; ++y)
      for (int x = a.x; x <= b.x; ++x) {
        uint h = contactBucket(ivec3(x, y, z), k >= u.triangle_count);
        bool again = false;
        for (uint j = 0u; j < count; ++j) again = again || seen[j] == h;
        if (again) continue;
        seen[count++] = h;
        if (scatter)
          contact_grid[contactEntries() + scratch[contactCounts() + h] + atomicAdd(scratch[contactFill() + h], 1u)] = k;
        else
          atomicAdd(scratch[contactCounts() + h], 1u);
      }
}

// The particle's step bound and nearest distance (ContactParticle.state)
void lowerNearest(uint i, float d2) { atomicMin(contact_particles[i].state.x, floatBitsToUint(d2)); }
bool contactFree(uint i) { return (contact_particles[i].state.y & 1u) != 0u; }

// A pair closer than the contact radius lowers its four particles' bounds; one closer than the
// thickness pushes them apart (contactPush, in fixed point)
void contactPair(uvec4 q, ContactPair c) {
  float r = u.contact.x, thickness = u.contact.z;
  if (!(c.d2 < r * r)) return;
  lowerNearest(q.x, c.d2);
  lowerNearest(q.y, c.d2);
  lowerNearest(q.z, c.d2);
  lowerNearest(q.w, c.d2);
  if (!(c.d2 < thickness * thickness)) return;
  vec4 x0 = pos[q.x], x1 = pos[q.y], x2 = pos[q.z], x3 = pos[q.w];
  for (uint j = 0u; j < 4u; ++j) {
    uint i = j == 0u ? q.x : (j == 1u ? q.y : (j == 2u ? q.z : q.w));
    ivec3 f = contactFixed(contactPush(x0, x1, x2, x3, c, thickness, j), u.contact.w);
    atomicAdd(contact_particles[i].sum.x, f.x);
    atomicAdd(contact_particles[i].sum.y, f.y);
    atomicAdd(contact_particles[i].sum.z, f.z);
    atomicAdd(contact_particles[i].sum.w, 1);
  }
}

// What a look-up of the grid does with the entries it finds (contactVisit)
#define CONTACT_VISIT_TRIANGLES 0u // particle `self` against the triangles near it
#define CONTACT_VISIT_EDGES 1u     // edge `self` against the edges after it
#define CONTACT_VISIT_CROSSING 2u  // live triangle slot `self` against the triangles whose boxes meet its box

// Particle i against live triangle slot t
void visitTriangle(uint i, uint t) {
  uvec4 tri = triangles[t];
  if (i == tri.x || i == tri.y || i == tri.z || contactFree(tri.x) || contactFree(tri.y) || contactFree(tri.z)) return;
  contactPair(uvec4(i, tri.x, tri.y, tri.z),
              pointTriangle(vec3(pos[i]), vec3(pos[tri.x]), vec3(pos[tri.y]), vec3(pos[tri.z])));
}

// Edge e against edge f > e that shares no particle with it
void visitEdge(uint e, uint f) {
  uvec2 a = contact_edges[e].xy, b = contact_edges[f].xy;
  if (f <= e || a.x == b.x || a.x == b.y || a.y == b.x || a.y == b.y) return;
  if (contactFree(a.x) || contactFree(a.y) || contactFree(b.x) || contactFree(b.y)) return;
  contactPair(uvec4(a, b), segmentSegment(vec3(pos[a.x]), vec3(pos[a.y]), vec3(pos[b.x]), vec3(pos[b.y])));
}

// Live triangle slot t against slot o: when they share no particle and cross, both are marked
void visitCrossing(uint t, uint o) {
  uvec4 a = triangles[t], b = triangles[o];
  if (a.x == b.x || a.x == b.y || a.x == b.z || a.y == b.x || a.y == b.y || a.y == b.z || a.z == b.x || a.z == b.y ||
      a.z == b.z)
    return;
  if (!trianglesCross(vec3(pos[a.x]), vec3(pos[a.y]), vec3(pos[a.z]), vec3(pos[b.x]), vec3(pos[b.y]), vec3(pos[b.z])))
    return;
  atomicOr(contact_grid[SIM_CONTACT_HEADER + t], 1u);
  atomicOr(contact_grid[SIM_CONTACT_HEADER + o], 1u);
  atomicOr(contact_grid[CONTACT_TANGLED], 1u);
}

// Every grid entry of the kind `visit` looks for whose box meets [lo, hi], once: in the cell of the
// low corner of the two boxes' overlap (both boxes span that cell)
void contactVisit(uint visit, uint self, vec3 lo, vec3 hi) {
  float inv = contactInvCell();
  ivec3 a = cellOf(lo, inv), b = min(cellOf(hi, inv), a + ivec3(4));
  uint entries = contactEntries(), edges_from = u.triangle_count;
  for (int z = a.z; z <= b.z; ++z)
    for (int y = a.y; y <= b.y; ++y)
      for (int x = a.x; x <= b.x; ++x) {
        ivec3 cell = ivec3(x, y, z);
        uint h = contactBucket(cell, visit == CONTACT_VISIT_EDGES);
        uint end = scratch[contactCounts() + h + 1u];
        for (uint m = scratch[contactCounts() + h]; m < end; ++m) {
          uint k = contact_grid[entries + m];
          vec3 elo, ehi;
          contactBox(k, elo, ehi);
          if (!boxesMeet(lo, hi, elo, ehi) || cellOf(max(lo, elo), inv) != cell) continue;
          if (visit == CONTACT_VISIT_TRIANGLES)
            visitTriangle(self, k);
          else if (visit == CONTACT_VISIT_EDGES)
            visitEdge(self, k - edges_from);
          else
            visitCrossing(self, k);
        }
      }
}

#endif
