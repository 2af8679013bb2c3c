// The GPU's penetration-free contact, the contact_* passes of the contact stage (contact.h has
// the maths and the proof). A hashed grid of the live triangles' and edges' boxes (count -> scan ->
// scatter; cells as wide as the longest edge and the contact diameter, so a box spans two cells a
// side at most) is built in a substep that needs it; the crossing check looks its triangles up in
// it. Each particle and each edge (a query) keeps a list of the primitives within contactReach of
// it, as the CPU's lists do: built from the grid when the particles' travel since the last build
// outgrew them (listsOutgrown; or the triangles, the radius or the audit say so), in the query's own slots, in
// the order of the grid; a query with more than its slots (u.contact_check.list_capacity) looks the grid up
// every substep. The grid's passes dispatch indirectly (contact_arm: no workgroups in a substep
// that does not build it), and between builds contact_walk runs over the queries with pairs alone
// (named in order at each build). A pair counts when its primitives are closer than the contact
// radius, exactly as on the CPU (CpuContact): the bounds are atomic minimums of float bits and the
// pushes integer sums (contactFixed), so neither depends on the order of the pairs or on when the
// lists were built, and the bits are the CPU's.
#ifndef SIM_CONTACT_GLSL
#define SIM_CONTACT_GLSL
#include "contact_grid.glsl"

// contact_cross: live triangle slot t in substep s. With the grid built: when crossingChecked names
// t, against every triangle whose box meets its box (once: in the cell of the low corner of the
// boxes' overlap, which both boxes span); the particles of two that cross go free.
void contactCross(uint t, uint s) {
  if (t >= counters.triangle_count || contactGoneWrong()) return;
  vec3 lo, hi;
  if (!gridBuilt()) return;
  uvec4 tri = triangles[t];
  uint was = contact_particles[tri.x].state.y | contact_particles[tri.y].state.y | contact_particles[tri.z].state.y;
  bool all = s == 0u && (contactChecks().mode & SIM_CONTACT_CHECK_ALL) != 0u;
  if (!crossingChecked(all, (was & 2u) != 0u)) return;
  loadBox(t, lo, hi);
  float inv = contactInvCell();
  ivec3 a = cellOf(lo, inv), b = min(cellOf(hi, inv), a + ivec3(4)), cell = a;
  if (any(lessThan(b, a))) return;
  do {
    uvec2 range = bucketRange(cell, false);
    for (uint m = range.x; m < range.y; ++m) {
      uint o = contact_words[contactEntries() + m];
      vec3 elo, ehi;
      loadBox(o, elo, ehi);
      if (boxesMeet(lo, hi, elo, ehi) && cellOf(max(lo, elo), inv) == cell) visitCrossing(t, o);
    }
  } while (nextCell(a, b, cell));
}

// Which queries contactNear takes: all (the fused tick), those that search the grid (contact_near:
// the lists are built, or theirs overflowed) or those that walk their lists (contact_walk, over the
// named queries within their slots: contactWalks)
#define NEAR_ALL 0u
#define NEAR_SEARCH 1u
#define NEAR_WALK 2u
// ... or every query's pairs at the start of the substep again, through its list or (overflowed)
// the grid, for the half-spaces of the steps (contact_pass, contact_excess, contact_share, over the
// named queries, those with pairs: slidePair)
#define NEAR_PASS 3u
#define NEAR_EXCESS 4u
#define NEAR_SHARE 5u
// ... or those half-spaces listed by particle for the settle stage: counted (contact_half_count),
// then, after the counts' scan, filled (contact_half_fill)
#define NEAR_HALF_COUNT 6u
#define NEAR_HALF_FILL 7u
// Candidates contactNearOf gathers before it weighs them
#define CONTACT_BATCH 16u

// Where contactNearOf weighs particle j: where it is, or where it started the substep (the
// half-spaces' passes, after the floor)
vec4 nearPosition(uint j, uint only) { return only >= NEAR_PASS ? contact_particles[j].start : SIM_POSITION(j); }

// The settle stage's half-spaces listed by particle (settle_bodies.h), in scratch from
// u.contact_check.half_offset: particle i's count, then (their exclusive scan) where its list starts
// (particles + 1 words), then its fill (particles words); the lists themselves (SlideHalf: five
// words each, SIM_CONTACT_HALF_CAPACITY a particle) after the queries' pair lists
uint halfStarts() { return contactChecks().half_offset; }
uint halfFills() { return contactChecks().half_offset + u.particle_count + 1u; }
uint halfEntries() { return listOf(u.particle_count + contactEdgeCount()); }
uint halfFirst(uint i) { return scratch[halfStarts() + i]; }
uint halfEnd(uint i) { return scratch[halfStarts() + i + 1u]; }
SlideHalf halfSpace(uint k) {
  uint w = halfEntries() + 5u * k;
  SlideHalf h;
  h.h = uintBitsToFloat(uvec4(contact_lists[w], contact_lists[w + 1u], contact_lists[w + 2u], contact_lists[w + 3u]));
  h.slack = uintBitsToFloat(contact_lists[w + 4u]);
  return h;
}
// Half-space h of particle i: counted, or put in its list (within the capacity)
void listHalf(uint i, SlideHalf h, uint only) {
  if (only == NEAR_HALF_COUNT) {
    atomicAdd(scratch[halfStarts() + i], 1u);
    return;
  }
  uint k = halfFirst(i) + atomicAdd(scratch[halfFills() + i], 1u);
  if (k >= SIM_CONTACT_HALF_CAPACITY * u.particle_count) return;
  uint w = halfEntries() + 5u * k;
  uvec4 bits = floatBitsToUint(h.h);
  contact_lists[w] = bits.x;
  contact_lists[w + 1u] = bits.y;
  contact_lists[w + 2u] = bits.z;
  contact_lists[w + 3u] = bits.w;
  contact_lists[w + 4u] = floatBitsToUint(h.slack);
}

// Particle j of pair q
uint pairParticle(uvec4 q, uint j) { return j == 0u ? q.x : (j == 1u ? q.y : (j == 2u ? q.z : q.w)); }

// The mean of what particle i is passed (contactPassed), summed by contact_pass
vec3 passedMean(uint i) { return contactAverage(ivec4(contact_particles[i].passed), contactKeys().fixed_units); }

// The half-spaces pair q sets its particles' steps in (slideConstraint; `edge`: two edges; x0..x3
// where they started the substep, c their nearest points): each step's excess beyond them passed
// on to the other primitive's particles (NEAR_PASS), or the excess of the step with its passed
// mean (passedPosition) summed into its particle's sums (NEAR_EXCESS), or the share of that step
// less that excess's mean that keeps them lowering its share (NEAR_SHARE), or listed by particle
// (NEAR_HALF_*)
void slidePair(uvec4 q, vec3 x0, vec3 x1, vec3 x2, vec3 x3, NearestPoints c, bool edge, uint only) {
  vec3 frame = contactFrameNow();
  for (uint j = 0u; j < 4u; ++j) {
    SlideHalf h = slideConstraint(x0, x1, x2, x3, c, edge, contactKeys().radius, contactKeys().fraction, j);
    if (h.h.w < 0.0f) continue;
    uint i = pairParticle(q, j);
    if (only >= NEAR_HALF_COUNT) {
      listHalf(i, h, only);
      continue;
    }
    vec3 start = vec3(contact_particles[i].start) + frame;
    if (only == NEAR_PASS) {
      vec3 e = slideExcess(h, vec3(SIM_POSITION(i)) - start);
      if (e == vec3(0.0f)) continue;
      for (uint k = 0u; k < 4u; ++k) {
        if (!contactOpposite(j, k, edge)) continue;
        uint o = pairParticle(q, k);
        vec4 x = SIM_POSITION(o); // whole (see contactSlideStep)
        if (x.w > 0.0f) addPassed(o, contactPassed(e, c, k));
      }
      continue;
    }
    vec3 step = passedPosition(SIM_POSITION(i), passedMean(i), u.floor_y) - start;
    if (only == NEAR_EXCESS) {
      vec3 e = slideExcess(h, step);
      if (e != vec3(0.0f)) addPush(i, e);
    } else {
      float share = slideShare(h, step + contactAverage(ivec4(contact_particles[i].sum), contactKeys().fixed_units));
      if (share < 1.0f) atomicMin(contact_particles[i].state.z, floatBitsToUint(share));
    }
  }
}

// contactNearOf's weighing of one candidate `other` of query k (a triangle for a particle, an
// edge for an edge): the pair's distance, listed `into` a list being built, then its bounds and
// pushes (or, from NEAR_PASS, its half-spaces); pairs sharing a particle are none, pairs with a
// free particle only listed.
void weighPair(uint k, uint other, bool particle, uvec2 edge, uint into, uint only) {
  // The pair's four particles: the particle and the triangle's three, or the two edges' two
  uvec4 q;
  if (particle) {
    uvec4 tri = triangles[other];
    if (k == tri.x || k == tri.y || k == tri.z) return;
    q = uvec4(k, tri.xyz);
  } else {
    uvec2 f = contactEdge(other).xy;
    if (edge.x == f.x || edge.x == f.y || edge.y == f.x || edge.y == f.y) return;
    q = uvec4(edge, f);
  }
  bool free = contactFree(q.x) || contactFree(q.y) || contactFree(q.z) || contactFree(q.w);
  if (free && into == SIM_NONE) return;
  vec3 x0 = vec3(nearPosition(q.x, only)), x1 = vec3(nearPosition(q.y, only)), x2 = vec3(nearPosition(q.z, only)),
       x3 = vec3(nearPosition(q.w, only));
  NearestPoints c = particle ? pointTriangle(x0, x1, x2, x3) : segmentSegment(x0, x1, x2, x3);
  if (only >= NEAR_PASS) {
    if (!free) slidePair(q, x0, x1, x2, x3, c, !particle, only);
    return;
  }
  if (into != SIM_NONE) listPair(into, c.d2, other);
  if (!free) contactPair(q, c);
}

// contact_near: query k (`particle`: k < particles), particle k (against the triangles near it) or edge
// e = k - particles (against the edges after it near it): through its list, or when the lists are
// built (or its list overflowed) through the grid, its box widened past the reach (or the radius):
// which pairs are kept and which count is their distance's call. One loop walks the candidates,
// the list's slots or the entries of the grid in the box's cells (a pair once: in the cell of the
// low corner of the two boxes' overlap), and one place weighs a pair: a CPU device runs every
// instruction of a kernel for each group of invocations, whatever the branches, so the kernel is
// kept short.
void contactNearOf(uint k, uint only, bool particle) {
  if (contactGoneWrong()) return;
  uint self = particle ? k : k - u.particle_count;
  uint list = listOf(k);
  bool build = only < NEAR_WALK && listsRebuilt();
  uint count = build ? 0u : contact_lists[list];
  // Through its list (which holds only live primitives: a tear builds the lists again)
  bool walk = only == NEAR_WALK || (!build && count <= contactChecks().list_capacity);
  if (walk && count == 0u) return;
  if (only == NEAR_SEARCH && walk) return;
  if (particle && !build && contactFree(k)) return;
  uvec2 edge = uvec2(0u);
  vec3 lo, hi;
  if (particle) {
    lo = vec3(nearPosition(k, only));
    hi = lo;
  } else {
    if (self >= contactEdgeCount() || !contactEdgeLive(self)) return;
    edge = contactEdge(self).xy;
    vec3 ea = vec3(nearPosition(edge.x, only)), eb = vec3(nearPosition(edge.y, only));
    lo = min(ea, eb);
    hi = max(ea, eb);
  }
  uint into = SIM_NONE;
  if (build) {
    into = list;
    contact_lists[list] = 0u;
    if (particle) {
      uint w = listBaseWord(k);
      contact_lists[w] = floatBitsToUint(lo.x);
      contact_lists[w + 1u] = floatBitsToUint(lo.y);
      contact_lists[w + 2u] = floatBitsToUint(lo.z);
    }
  }
  float reach = build ? 1.01f * contactReach(contactKeys().radius) : 1.01f * contactKeys().radius;
  lo -= vec3(reach);
  hi += vec3(reach);
  float inv = contactInvCell();
  ivec3 a = cellOf(lo, inv), b = min(cellOf(hi, inv), a + ivec3(4)), cell = a;
  if (!walk && any(lessThan(b, a))) return;
  uvec2 range = walk ? uvec2(0u, count) : bucketRange(cell, !particle);
  uint entries = contactEntries(), edges_from = u.triangle_count;
  // Rounds of two loops: the next candidates whose boxes meet (at most CONTACT_BATCH), then those
  // weighed; a CPU device runs a loop's body as often as its busiest invocation needs, so the
  // costly weighing runs once a candidate, not once an entry of the grid
  uint batch[CONTACT_BATCH];
  for (bool more = true; more;) {
    uint found = 0u;
    for (;;) {
      if (range.x >= range.y) {
        more = !walk && nextCell(a, b, cell);
        if (!more) break;
        range = bucketRange(cell, !particle);
        continue;
      }
      uint m = range.x++;
      if (walk) {
        batch[found] = contact_lists[list + 1u + m];
      } else {
        uint e = contact_words[entries + m];
        if (!particle && e - edges_from <= self) continue; // each pair from its first edge
        vec3 elo, ehi;
        loadBox(e, elo, ehi);
        if (!boxesMeet(lo, hi, elo, ehi) || cellOf(max(lo, elo), inv) != cell) continue;
        batch[found] = particle ? e : e - edges_from;
      }
      if (++found == CONTACT_BATCH) break;
    }
    for (uint j = 0u; j < found; ++j) weighPair(k, batch[j], particle, edge, into, only);
  }
}

// Query k (contactNearOf): the particles' and the edges' bodies apart, each weighing only its kind
// of pair (a CPU device runs both bodies for a group of invocations, but each loop only as often as
// its own queries need)
void contactNear(uint k, uint only) {
  if (k < u.particle_count)
    contactNearOf(k, only, true);
  else
    contactNearOf(k, only, false);
}

// Where the queries with pairs in their lists are named, after the boxes (contact_emit)
uint activeWord() { return contactBoxWord(u.triangle_count + contactEdgeCount()); }
// True when query k has pairs in its list (it is named until the next build)
bool contactActive(uint k) { return contact_lists[listOf(k)] > 0u; }
// True when query k has pairs in its list, all in its slots (contact_walk walks it until the next
// build; one whose list overflowed searches the grid every substep, contact_near)
bool contactWalks(uint k) { return contact_lists[listOf(k)] <= contactChecks().list_capacity; }

// contact_active: query k's flag, 1 when it has pairs in its list (the end, k = queries: 0), at
// scratch offset `flags` (scanned in place next)
void contactActiveFlag(uint k, uint flags) {
  scratch[flags + k] = k < u.particle_count + contactEdgeCount() && !contactGoneWrong() && contactActive(k) ? 1u : 0u;
}

// contact_emit: active query k named at its place (the flags' scan); the end (k = queries) says how
// many there are, in the named queries' arguments (Grid::Named) for the substeps until the next
// build, which contact_walk's copy (contact_arm)
void contactEmit(uint k, uint flags) {
  uint queries = u.particle_count + contactEdgeCount();
  if (k == queries) {
    uint named = scratch[flags + queries];
    uvec4 args = uvec4(groupGrid((named + SIM_WG_PARTICLES - 1u) / SIM_WG_PARTICLES), 1u, named);
    hash_args[SIM_CONTACT_WALK_ARGS + 1u] = args;
#ifdef SIM_BATCH_PASS
    // A fleet: the batch's named queries of this substep cover this sheet's anew
    batchRaiseArgs(
        SIM_BATCH_ARGS_LIVE_CONTACT + batch.substep * SIM_BATCH_CONTACT_SLOTS + SIM_CONTACT_GRID_DISPATCHES + 2u, args);
#endif
    // Named for this build (contact_bound counts it after the walk)
    if (listsRebuilt()) contact_lists[listHeader() + LIST_NAMED] = contact_lists[listHeader() + LIST_BUILDS] + 1u;
  } else if (k < queries && !contactGoneWrong() && contactActive(k)) {
    contact_words[activeWord() + scratch[flags + k]] = k;
  }
}

// The j-th named query (Grid::Named), or SIM_NONE past them
uint namedQuery(uint j) {
  return j < hash_args[SIM_CONTACT_WALK_ARGS + 1u].w ? contact_words[activeWord() + j] : SIM_NONE;
}

// contact_walk: the j-th named query, when it walks its list
void contactWalk(uint j) {
  uint k = j < walkArgs().w ? namedQuery(j) : SIM_NONE; // none while the lists are built
  if (k != SIM_NONE && contactWalks(k)) contactNear(k, NEAR_WALK);
}

// contact_bound: particle i's step bound (stepBound; unbounded when free) and push
// (contactAverage); the particles in contact counted; the substep's frame (contactFrame)
void contactBound(uint i, uint s) {
  float r = contactKeys().radius;
  if (i == 0u && listsRebuilt()) {
    // The lists stand for these triangles and this radius (none when the positions went wrong)
    contact_lists[listHeader() + LIST_KEY] = contactGoneWrong() ? 0u : counters.triangle_count + 1u;
    contact_lists[listHeader() + LIST_RADIUS] = floatBitsToUint(r);
    contact_lists[listHeader() + LIST_BUILDS] += 1u;
    contact_lists[listHeader() + LIST_SEARCH] = contact_words[CONTACT_OVERFLOW];
  }
  if (i == 0u) {
    // The substep's frame, once (contactFrameNow)
    bool none = contact_words[CONTACT_FRAME_LO] > contact_words[CONTACT_FRAME_HI]; // no particles
    vec3 t = none ? vec3(0.0f)
                  : contactFrame(gatheredCorner(CONTACT_FRAME_LO), gatheredCorner(CONTACT_FRAME_HI),
                                 uintBitsToFloat(contact_words[CONTACT_LOWEST]), contactFrameScale(u.verlet, s));
    contact_words[CONTACT_FRAME] = floatBitsToUint(t.x);
    contact_words[CONTACT_FRAME + 1u] = floatBitsToUint(t.y);
    contact_words[CONTACT_FRAME + 2u] = floatBitsToUint(t.z);
  }
  uvec4 state = contact_particles[i].state;
  uint nearest = contactGoneWrong() ? 0u : state.x;
  if (nearest < floatBitsToUint(r * r)) atomicAdd(contact_words[CONTACT_COUNT], 1u);
  contact_particles[i].start.w = contactFreeState(state)
                                     ? uintBitsToFloat(0x7F800000u)
                                     : slideBound(uintBitsToFloat(nearest), r, contactKeys().fraction);
  contact_particles[i].push =
      vec4(contactPushWithin(contactAverage(ivec4(contact_particles[i].sum), contactKeys().fixed_units),
                             uintBitsToFloat(nearest), r),
           0.0f);
}

// The floor's step with contact (after floor.comp, contact_pass, contact_excess and contact_share):
// particle i's step with what it is passed (passedState) less the frame cut to its pairs'
// half-spaces (the excess's mean taken out, the rest cut to the share), then to its bound, then
// pushed (slideStep)
VerletState contactSlideStep(uint i, VerletState st, uint s) {
  // The grab's target, start and bound each in one load: a fleet's lavapipe build reads a component
  // loaded apart from its vector as the vector's first
  // (SpirvRules.NoSimShaderLoadsAVectorAndOneOfItsComponentsByDeviceAddress)
  vec4 target = u.grab_target[s];
  if (!contactBounded(st.position.w, i == u.grab_index, target.w)) return st;
  vec4 start = contact_particles[i].start;
  st = passedState(st, passedMean(i), u.floor_y);
  return slideStep(st, vec3(start), vec3(contact_particles[i].push),
                   contactAverage(ivec4(contact_particles[i].sum), contactKeys().fixed_units),
                   uintBitsToFloat(contact_particles[i].state.z), start.w, contactFrameNow());
}

// What the floor pass leaves for the half-spaces' passes: particle i's sums cleared for what it is
// passed and its excess, and its share whole; with the settle on, its half-spaces' count and fill
// cleared
void contactSlideClear(uint i) {
  contact_particles[i].sum = uvec4(0u);
  contact_particles[i].passed = uvec4(0u);
  contact_particles[i].state.z = floatBitsToUint(1.0f);
  if (contactChecks().sweeps == 0u) return;
  scratch[halfStarts() + i] = 0u;
  scratch[halfFills() + i] = 0u;
  if (i == 0u) scratch[halfStarts() + u.particle_count] = 0u;
}

// The settle stage (settle_bodies.h) reads where each particle started the substep, its push and
// ball, its half-spaces (above) and the substep's frame
vec3 settleStart(uint i) { return vec3(contact_particles[i].start); }
vec3 settlePush(uint i) { return vec3(contact_particles[i].push); }
float settleBound(uint i) {
  vec4 start = contact_particles[i].start; // whole, as settleStart reads it (see contactSlideStep)
  return start.w;
}
vec3 settleFrame() { return contactFrameNow(); }
#include "settle_bodies.h"

// contact_settle_check: constraint slot k over the limit in substep s (settleOver; a torn one past
// its colour's live count may say so too: that only runs a stage that moves nothing); true for the
// one that starts the stage (the first of the substep found over)
bool contactSettleCheck(uint k, uint s) {
  return contactChecks().sweeps > 0u && settleOver(constraints[k], s) &&
         atomicOr(contact_words[CONTACT_SETTLE_OVER], 1u) == 0u;
}
// True when an edge is over the limit as the stage starts: else it lists nothing and moves nothing
bool settleStarts() { return contact_words[CONTACT_SETTLE_OVER] != 0u; }
// True when sweep `sweep` runs: the first when the stage starts, a later one when the last worked
// on an edge (a sweep that moved nothing leaves the next nothing to move: the bits are the same)
bool settleSweeps(uint sweep) {
  return sweep == 0u ? settleStarts() : contact_words[CONTACT_SETTLE_SWEPT + sweep - 1u] != 0u;
}
// contact_settle: constraint c in sweep `sweep` of substep s; true for the first edge of the sweep
// it works on (the sweep is not the last that moves anything)
bool contactSettle(Constraint c, uint sweep, uint s) {
  return settleConstraint(c, s) && atomicOr(contact_words[CONTACT_SETTLE_SWEPT + sweep], 1u) == 0u;
}

#ifndef SIM_FUSED_CONTACT
// The per-colour passes dispatch the settle's indirectly (Grid::Settle, Grid::Sweep): none of its
// passes runs a workgroup in a substep that does not need it. contact_begin disarms every slot;
// the edge that starts the stage arms slot 0 (the half-spaces' passes, over the named queries:
// namedQuery) and 1 (the first sweep), the first edge a sweep works on arms the next sweep's. A
// sheet of a fleet raises the batch's slot.
void disarmSettle() {
  for (uint k = 0u; k < SIM_CONTACT_SETTLE_SLOTS; ++k) hash_args[SIM_CONTACT_SETTLE_ARGS + k] = uvec4(0u, 1u, 1u, 0u);
}
void armSettle(uint slot) {
  uvec4 named = hash_args[SIM_CONTACT_WALK_ARGS + 1u];
#ifdef SIM_BATCH_PASS
  uint live = SIM_BATCH_ARGS_LIVE_SETTLE + batch.substep * SIM_CONTACT_SETTLE_SLOTS + slot;
  if (slot > 0u)
    batchArmArgs(live, SIM_BATCH_ARGS_FULL_SETTLE);
  else
    batchRaiseArgs(live, named);
#else
  hash_args[SIM_CONTACT_SETTLE_ARGS + slot] = slot > 0u ? hash_args[SIM_CONTACT_SETTLE_FULL] : named;
#endif
}
#endif

#endif
