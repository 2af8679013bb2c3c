// The GPU contact's words and grid (contact.glsl has the passes that use them): the header's words,
// the hashed grid's boxes and buckets, the lists' slots, how a pair adds to its particles' sums,
// and the bodies that ready them each substep (contact_begin, contact_clear, contact_arm,
// contact_grid_clear).
#ifndef SIM_CONTACT_GRID_GLSL
#define SIM_CONTACT_GRID_GLSL
#include "sim_common.glsl"
// The position of particle j: its buffer, or the fused tick's shared copy
#ifndef SIM_POSITION
#define SIM_POSITION(j) pos[j]
#endif

// Words of the grid's header (SIM_CONTACT_HEADER)
#define CONTACT_LONGEST 0u
#define CONTACT_TANGLED 1u
#define CONTACT_COUNT 2u
#define CONTACT_REBUILD 3u
#define CONTACT_GRID SIM_CONTACT_WORD_GRID
#define CONTACT_OVERFLOW 5u
// contactFrame's inputs, gathered by contact_clear: every particle's last step, lowest (3 words)
// and highest (3 words) as orderedBits, and the bits of their lowest start above the floor
#define CONTACT_FRAME_LO 8u
#define CONTACT_FRAME_HI 11u
#define CONTACT_LOWEST 14u
// The particles' travel since the lists were built, lowest (3 words) and highest (3 words) as
// orderedBits (contactTravelled)
#define CONTACT_TRAVEL_LO 15u
#define CONTACT_TRAVEL_HI 18u
// The substep's frame (3 words, float bits): contact_bound works it out once for the floor's steps
#define CONTACT_FRAME 21u
// The settle's: 1 when an edge is over the limit as the stage starts (settleOver), then per sweep 1
// when it worked on an edge (SIM_SETTLE_MAX_SWEEPS words)
#define CONTACT_SETTLE_OVER 24u
#define CONTACT_SETTLE_SWEPT 25u
// Words of the lists' header (SIM_CONTACT_LIST_HEADER): the triangle count + 1 they were built for
// (0: none stand), the bits of the radius, the builds so far
#define LIST_KEY 0u
#define LIST_RADIUS 1u
#define LIST_BUILDS 2u
#define LIST_SEARCH 3u // 1: a query overflowed its slots at the last build (it searches the grid)
#define LIST_NAMED 4u  // the builds when contact_emit last named the queries with pairs (contact_walk's)

// The entries of the grid, after the header: an entry k is live triangle slot k
// (k < u.triangle_count) or edge k - u.triangle_count
uint contactEntries() { return SIM_CONTACT_HEADER; }
uint contactCounts() { return contactGrid().counts; }
uint contactFill() { return contactGrid().fills; }
uint contactEdgeCount() { return contactGrid().edges; }

// True when triangle id `id` is live (its two edge constraints stand, as the compaction keeps it)
bool contactTriangleLive(uint id) {
  if (id == SIM_NONE) return false;
  uvec2 e = tri_edges[id];
  return torn[e.x] == 0u && torn[e.y] == 0u;
}

// Edge e of SIM_BIND_CONTACT_LISTS: its particles, the triangles that hold it
uvec4 contactEdge(uint e) {
  return uvec4(contact_lists[4u * e], contact_lists[4u * e + 1u], contact_lists[4u * e + 2u],
               contact_lists[4u * e + 3u]);
}

// True when edge e belongs to a live triangle
bool contactEdgeLive(uint e) {
  uvec4 edge = contactEdge(e);
  return contactTriangleLive(edge.z) || contactTriangleLive(edge.w);
}

// The positions went wrong (an edge of no finite length): no pair is looked for and nothing moves,
// as on the CPU
bool contactGoneWrong() { return contact_words[CONTACT_LONGEST] >= 0x7F800000u; }

// The lists' header, after the edges
uint listHeader() { return 4u * contactEdgeCount(); }
// Where particle i was when the lists were built
uint listBaseWord(uint i) { return listHeader() + SIM_CONTACT_LIST_HEADER + 4u * i; }
vec3 listBase(uint i) {
  uint w = listBaseWord(i);
  return uintBitsToFloat(uvec3(contact_lists[w], contact_lists[w + 1u], contact_lists[w + 2u]));
}
// The list of query k (particle k, or edge k - particles): its count, then its pairs
uint listOf(uint k) { return listBaseWord(u.particle_count) + (1u + SIM_CONTACT_LIST_CAPACITY) * k; }
// True when the lists are built in this substep
bool listsRebuilt() { return contact_words[CONTACT_REBUILD] != 0u; }
// True when the grid is built in this substep: the lists are, a query searches it, or the crossing
// check looks at a triangle
bool gridBuilt() { return contact_words[CONTACT_GRID] != 0u; }

// Cells per unit of length: the cells are SIM_CONTACT_CELL_ROOM x the longest live edge or the
// contact diameter, whichever is longer
float contactInvCell() {
  float longest = simSqrt(uintBitsToFloat(contact_words[CONTACT_LONGEST]));
  return simDiv(1.0f, SIM_CONTACT_CELL_ROOM * max(longest, 2.0f * contactKeys().radius));
}

// True when grid entry k is a live triangle slot or a live edge
bool contactLive(uint k) {
  if (k < u.triangle_count) return k < counters.triangle_count;
  uint e = k - u.triangle_count;
  return e < contactEdgeCount() && contactEdgeLive(e);
}

// The box of grid entry k (a live triangle slot or a live edge) from the positions; false when k is neither
bool contactBox(uint k, out vec3 lo, out vec3 hi) {
  if (k < u.triangle_count) {
    if (k >= counters.triangle_count) return false;
    uvec4 t = triangles[k];
    vec3 a = vec3(SIM_POSITION(t.x)), b = vec3(SIM_POSITION(t.y)), c = vec3(SIM_POSITION(t.z));
    lo = min(a, min(b, c));
    hi = max(a, max(b, c));
    return true;
  }
  uint e = k - u.triangle_count;
  if (e >= contactEdgeCount() || !contactEdgeLive(e)) return false;
  uvec2 edge = contactEdge(e).xy;
  vec3 a = vec3(SIM_POSITION(edge.x)), b = vec3(SIM_POSITION(edge.y));
  lo = min(a, b);
  hi = max(a, b);
  return true;
}

// The boxes of the grid's live entries, as the count pass found them (six words each, after the
// entries' SIM_CONTACT_CELLS_PER_BOX words per entry): a look-up reads two vectors instead of the
// corners' positions
uint contactBoxWord(uint k) {
  return contactEntries() + SIM_CONTACT_CELLS_PER_BOX * (u.triangle_count + contactEdgeCount()) + 6u * k;
}
void storeBox(uint k, vec3 lo, vec3 hi) {
  uint w = contactBoxWord(k);
  contact_words[w] = floatBitsToUint(lo.x);
  contact_words[w + 1u] = floatBitsToUint(lo.y);
  contact_words[w + 2u] = floatBitsToUint(lo.z);
  contact_words[w + 3u] = floatBitsToUint(hi.x);
  contact_words[w + 4u] = floatBitsToUint(hi.y);
  contact_words[w + 5u] = floatBitsToUint(hi.z);
}
void loadBox(uint k, out vec3 lo, out vec3 hi) {
  uint w = contactBoxWord(k);
  lo = uintBitsToFloat(uvec3(contact_words[w], contact_words[w + 1u], contact_words[w + 2u]));
  hi = uintBitsToFloat(uvec3(contact_words[w + 3u], contact_words[w + 4u], contact_words[w + 5u]));
}

// True when the closed boxes [lo, hi] and [elo, ehi] meet
bool boxesMeet(vec3 lo, vec3 hi, vec3 elo, vec3 ehi) {
  return lo.x <= ehi.x && elo.x <= hi.x && lo.y <= ehi.y && elo.y <= hi.y && lo.z <= ehi.z && elo.z <= hi.z;
}

// The bucket of a cell: the triangles' in the first half of the table, the edges' in the second, so
// that a look-up reads only the kind it looks for
uint contactBucket(ivec3 cell, bool edge) {
  return hashCell(cell, contactGrid().mask) + (edge ? contactGrid().mask + 1u : 0u);
}

// The buckets of the cells a box of grid entry k spans, each once (two cells of a box may share a
// bucket): counted (scatter false), which keeps the box, or filled with k (scatter true)
void contactInsert(uint k, bool scatter) {
  vec3 lo, hi;
  if (contactGoneWrong() || !gridBuilt()) return;
  if (scatter) {
    if (!contactLive(k)) return;
    loadBox(k, lo, hi);
  } else {
    if (!contactBox(k, lo, hi)) return;
    storeBox(k, lo, hi);
  }
  float inv = contactInvCell();
  ivec3 a = cellOf(lo, inv), span = min(cellOf(hi, inv), a + ivec3(1)) - a;
  bool edge = k >= u.triangle_count;
  // Cell c of the box (bits: x, y, z steps), unless an earlier cell has its bucket
  for (uint c = 0u; c < SIM_CONTACT_CELLS_PER_BOX; ++c) {
    ivec3 step = ivec3(int(c & 1u), int((c >> 1) & 1u), int(c >> 2));
    if (any(greaterThan(step, span))) continue;
    uint h = contactBucket(a + step, edge);
    bool again = false;
    for (uint e = 0u; e < c; ++e) {
      ivec3 earlier = ivec3(int(e & 1u), int((e >> 1) & 1u), int(e >> 2));
      again = again || (all(lessThanEqual(earlier, span)) && contactBucket(a + earlier, edge) == h);
    }
    if (again) continue;
    if (scatter)
      contact_words[contactEntries() + scratch[contactCounts() + h] + atomicAdd(scratch[contactFill() + h], 1u)] = k;
    else
      atomicAdd(scratch[contactCounts() + h], 1u);
  }
}

// The particle's step bound and nearest distance (ContactParticle.state)
void lowerNearest(uint i, float d2) { atomicMin(contact_particles[i].state.x, floatBitsToUint(d2)); }
bool contactFreeState(uvec4 state) { return (state.y & 1u) != 0u; }
bool contactFree(uint i) { return contactFreeState(contact_particles[i].state); }

// A pair closer than the contact radius lowers its four particles' bounds; one closer than the
// thickness pushes them apart (contactPush, in fixed point)
// Adds a push to particle i's sum in fixed point (contactFixed) and counts it
void addPush(uint i, vec3 push) {
  ivec3 f = contactFixed(push, contactKeys().fixed_units);
  // Two's complement: unsigned sums have the bits of the signed ones
  atomicAdd(contact_particles[i].sum.x, uint(f.x));
  atomicAdd(contact_particles[i].sum.y, uint(f.y));
  atomicAdd(contact_particles[i].sum.z, uint(f.z));
  atomicAdd(contact_particles[i].sum.w, 1u);
}
// Adds what particle i is passed (contactPassed) to its passed sum in fixed point and counts it
void addPassed(uint i, vec3 passed) {
  ivec3 f = contactFixed(passed, contactKeys().fixed_units);
  atomicAdd(contact_particles[i].passed.x, uint(f.x));
  atomicAdd(contact_particles[i].passed.y, uint(f.y));
  atomicAdd(contact_particles[i].passed.z, uint(f.z));
  atomicAdd(contact_particles[i].passed.w, 1u);
}

void contactPair(uvec4 q, NearestPoints c) {
  float r = contactKeys().radius, thickness = contactKeys().thickness;
  if (!(c.d2 < r * r)) return;
  lowerNearest(q.x, c.d2);
  lowerNearest(q.y, c.d2);
  lowerNearest(q.z, c.d2);
  lowerNearest(q.w, c.d2);
  if (!(c.d2 < thickness * thickness)) return;
  vec4 x0 = SIM_POSITION(q.x), x1 = SIM_POSITION(q.y), x2 = SIM_POSITION(q.z), x3 = SIM_POSITION(q.w);
  for (uint j = 0u; j < 4u; ++j) {
    uint i = j == 0u ? q.x : (j == 1u ? q.y : (j == 2u ? q.z : q.w));
    addPush(i, contactPush(x0, x1, x2, x3, c, thickness, j));
  }
}

// A pair of query `list` found by a build: kept when within contactReach (in the first
// u.contact_check.list_capacity of its slots; the count goes on past them)
void listPair(uint list, float d2, uint other) {
  float reach = contactReach(contactKeys().radius);
  if (!(d2 < reach * reach)) return;
  uint c = contact_lists[list];
  if (c < contactChecks().list_capacity)
    contact_lists[list + 1u + c] = other;
  else if (c == contactChecks().list_capacity)
    contact_words[CONTACT_OVERFLOW] = 1u;
  contact_lists[list] = c + 1u;
}

// Live triangle slot t against slot o: when they share no particle and cross, both triangles'
// particles go free this substep, and take their pushes that untangle the pair (untanglePush)
void visitCrossing(uint t, uint o) {
  uvec4 a = triangles[t], b = triangles[o];
  if (a.x == b.x || a.x == b.y || a.x == b.z || a.y == b.x || a.y == b.y || a.y == b.z || a.z == b.x || a.z == b.y ||
      a.z == b.z)
    return;
  vec3 x[6] = {vec3(SIM_POSITION(a.x)), vec3(SIM_POSITION(a.y)), vec3(SIM_POSITION(a.z)),
               vec3(SIM_POSITION(b.x)), vec3(SIM_POSITION(b.y)), vec3(SIM_POSITION(b.z))};
  if (!trianglesCross(x[0], x[1], x[2], x[3], x[4], x[5])) return;
  for (uint k = 0u; k < 6u; ++k) {
    uint i = k < 3u ? a[k] : b[k - 3u];
    atomicOr(contact_particles[i].state.y, 1u);
    vec3 push = untanglePush(x[0], x[1], x[2], x[3], x[4], x[5], contactKeys().thickness, k);
    if (push != vec3(0.0f)) addPush(i, push);
  }
  atomicOr(contact_words[CONTACT_TANGLED], 1u);
}

// The cells [a, b] of a box, x fastest, then y, then z: the next after `cell`; false past the last
bool nextCell(ivec3 a, ivec3 b, inout ivec3 cell) {
  if (++cell.x <= b.x) return true;
  cell.x = a.x;
  if (++cell.y <= b.y) return true;
  cell.y = a.y;
  return ++cell.z <= b.z;
}

// Where the entries of `cell`'s bucket of triangles (or of edges) start and end in the grid
uvec2 bucketRange(ivec3 cell, bool edge) {
  uint h = contactBucket(cell, edge);
  return uvec2(scratch[contactCounts() + h], scratch[contactCounts() + h + 1u]);
}

// The passes' bodies, one element each (the contact_* kernels, and the fused tick's loops)

// contact_begin: the header cleared (one invocation); the lists are built again in substep s when
// none stand, the triangles or the radius changed, the audit checks every triangle, or (`passes`:
// the contact_* passes, not the fused tick) contact_emit did not name the queries of the last build
// (the particles' travel outgrew them: contactTravelled after contact_clear), and the grid when they are, when a
// list overflowed at the last build, or when crossingChecked names triangles: the audit or a
// particle free in the last substep (a triangle crossed)
void contactBegin(uint s, bool passes) {
  bool crossed = contact_words[CONTACT_TANGLED] != 0u;
  for (uint w = 0u; w < SIM_CONTACT_HEADER; ++w) contact_words[w] = 0u;
  for (uint c = 0u; c < 3u; ++c) { // none yet
    contact_words[CONTACT_FRAME_LO + c] = 0xFFFFFFFFu;
    contact_words[CONTACT_TRAVEL_LO + c] = 0xFFFFFFFFu;
  }
  contact_words[CONTACT_LOWEST] = 0x7F800000u;
  bool audit = s == 0u && (contactChecks().mode & SIM_CONTACT_CHECK_ALL) != 0u;
  bool stand = contact_lists[listHeader() + LIST_KEY] == counters.triangle_count + 1u &&
               contact_lists[listHeader() + LIST_RADIUS] == floatBitsToUint(contactKeys().radius) && !audit;
  // The passes walk the queries contact_emit named: lists the fused tick built are built again
  if (passes) stand = stand && contact_lists[listHeader() + LIST_NAMED] == contact_lists[listHeader() + LIST_BUILDS];
  if (!stand) contact_words[CONTACT_REBUILD] = 1u;
  if (!stand || audit || crossed || contact_lists[listHeader() + LIST_SEARCH] != 0u) contact_words[CONTACT_GRID] = 1u;
}

// Lowest (w = 0) or highest (w = 1) of a box contact_clear gathered at word w0 (orderedBits)
vec3 gatheredCorner(uint w0) {
  return vec3(orderedFloat(contact_words[w0]), orderedFloat(contact_words[w0 + 1u]),
              orderedFloat(contact_words[w0 + 2u]));
}

// One invocation after contact_clear: the lists (and the grid) are built in this substep when the
// particles' travel since the last build outgrew them (listsOutgrown)
void contactTravelled() {
  if (listsOutgrown(gatheredCorner(CONTACT_TRAVEL_LO), gatheredCorner(CONTACT_TRAVEL_HI), contactKeys().radius)) {
    contact_words[CONTACT_REBUILD] = 1u;
    contact_words[CONTACT_GRID] = 1u;
  }
}

// The translation taken out of this substep's steps (contactFrame, from what contact_clear
// gathered), as contact_bound kept it
vec3 contactFrameNow() {
  return uintBitsToFloat(
      uvec3(contact_words[CONTACT_FRAME], contact_words[CONTACT_FRAME + 1u], contact_words[CONTACT_FRAME + 2u]));
}

// Elements contact_clear covers: the particles, the edges
uint contactSlots() { return max(u.particle_count, contactEdgeCount()); }
// Elements contact_grid_clear covers: the buckets and their end
uint contactBucketSlots() { return 2u * (contactGrid().mask + 1u) + 1u; }

// contact_clear: particle k's start of the substep, its travel since the lists were built into the
// box contactTravelled looks at, and its last step and height above the floor into the frame's
// inputs; edge k's squared length raises the longest
void contactClear(uint k) {
  if (k < u.particle_count) {
    float r = contactKeys().radius;
    vec4 x = SIM_POSITION(k);
    vec3 step = vec3(x) - vec3(prev[k]);
    for (uint c = 0u; c < 3u; ++c) {
      atomicMin(contact_words[CONTACT_FRAME_LO + c], orderedBits(step[c]));
      atomicMax(contact_words[CONTACT_FRAME_HI + c], orderedBits(step[c]));
    }
    float height = x.y - u.floor_y;
    atomicMin(contact_words[CONTACT_LOWEST], floatBitsToUint(height > 0.0f ? height : 0.0f));
    contact_particles[k].start = SIM_POSITION(k);
    // Free in the last substep: bit 1 (crossingChecked looks at its triangles again)
    contact_particles[k].state = uvec4(floatBitsToUint(r * r), (contact_particles[k].state.y & 1u) << 1, 0u, 0u);
    contact_particles[k].sum = uvec4(0u);
    vec3 d = vec3(SIM_POSITION(k)) - listBase(k);
    for (uint c = 0u; c < 3u; ++c) {
      atomicMin(contact_words[CONTACT_TRAVEL_LO + c], orderedBits(d[c]));
      atomicMax(contact_words[CONTACT_TRAVEL_HI + c], orderedBits(d[c]));
    }
  }
  if (k < contactEdgeCount() && contactEdgeLive(k)) {
    uvec2 edge = contactEdge(k).xy;
    vec3 d = vec3(SIM_POSITION(edge.y)) - vec3(SIM_POSITION(edge.x));
    atomicMax(contact_words[CONTACT_LONGEST], floatBitsToUint(dot3(d, d)));
  }
}

// contact_arm: whether the particles' travel builds the lists (contactTravelled), then the live
// indirect arguments of the grid's passes (Grid::Contact), their full grids
// when the grid is built in this substep, else no workgroups: a substep that does not build it
// dispatches none of them (a CPU device runs every instruction of a kernel for each group of
// invocations, even those that return at once)
void contactArm() {
  contactTravelled();
  bool built = gridBuilt();
  for (uint k = 0u; k < SIM_CONTACT_GRID_DISPATCHES; ++k)
    hash_args[SIM_CONTACT_GRID_ARGS + k] =
        built ? hash_args[SIM_CONTACT_GRID_ARGS + SIM_CONTACT_GRID_DISPATCHES + k] : uvec4(0u, 1u, 1u, 0u);
  // contact_walk: the queries with pairs at the last build, unless the lists are built now
  hash_args[SIM_CONTACT_WALK_ARGS] = listsRebuilt() ? uvec4(0u, 1u, 1u, 0u) : hash_args[SIM_CONTACT_WALK_ARGS + 1u];
  // contact_cross: every triangle when the grid is built
  hash_args[SIM_CONTACT_CROSS_ARGS] =
      built ? uvec4(groupGrid((u.triangle_count + SIM_WG_PARTICLES - 1u) / SIM_WG_PARTICLES), 1u, 0u)
            : uvec4(0u, 1u, 1u, 0u);
#ifdef SIM_BATCH_PASS
  // A fleet: the batch's live arguments of this substep cover this sheet's (the gates keep the
  // other sheets out of the passes this one alone needs)
  uint live = SIM_BATCH_ARGS_LIVE_CONTACT + batch.substep * SIM_BATCH_CONTACT_SLOTS;
  if (built)
    for (uint k = 0u; k < SIM_CONTACT_GRID_DISPATCHES; ++k) batchArmArgs(live + k, SIM_BATCH_ARGS_FULL_CONTACT + k);
  for (uint k = 0u; k < 3u; ++k) // contact_walk's, contact_cross's, the named queries' (as named so far)
    batchRaiseArgs(
        live + SIM_CONTACT_GRID_DISPATCHES + k,
        hash_args[k == 0u ? SIM_CONTACT_WALK_ARGS : (k == 1u ? SIM_CONTACT_CROSS_ARGS : SIM_CONTACT_WALK_ARGS + 1u)]);
#endif
}

// contact_grid_clear: bucket k cleared when the grid is built (dispatched only then: contact_arm)
void contactGridClear(uint k) {
  if (!gridBuilt()) return;
  uint buckets = 2u * (contactGrid().mask + 1u); // the triangles' and the edges'
  if (k <= buckets) scratch[contactCounts() + k] = 0u;
  if (k < buckets) scratch[contactFill() + k] = 0u;
}

#endif
