// The fused tick of small sheets (tick_fused.comp: one sheet; tick_batch.comp: one sheet of a
// fleet per workgroup, SIM_BATCH). Small sheets: substeps p.first_substep .. + p.substeps of a tick (on a GPU the whole
// tick, on a CPU device one substep) in one dispatch of one workgroup. Positions stay in shared memory from the first
// substep to the last; a workgroup barrier replaces each dispatch and pipeline barrier of the per-colour passes. Every
// substep runs the same per-particle and per-constraint maths, in the same order, as contact_*, integrate, project,
// hash_*, collide, floor and tear_*; the hash is built in the same buffers. Each invocation owns the particles lid, lid
// + kInvocations, ... (integration, collision and floor of a particle run on one invocation, so the collision delta
// stays in a register). Workgroup size: at most SIM_WG_FUSED, specialised per device (sim_common.glsl declares it)
#define SIM_LOCAL_SIZE SIM_WG_FUSED
#define SIM_LOCAL_SIZE_SPECIALIZED
// Invocations exchange data through buffers between barriers
#define SIM_COHERENT coherent
#define SIM_PUSH_TYPE FusedPush
#include "sim_common.glsl"
// As many positions as the device's shared memory holds (specialised: fusedCapacity)
layout(constant_id = SIM_SPEC_FUSED_CAPACITY) const uint kFusedCapacity = 1u;
shared vec4 s_pos[kFusedCapacity];
#define SIM_POSITION(j) s_pos[j]
#include "sim_elements.glsl"
#ifdef SIM_FUSED_CONTACT
// tick_fused_contact.comp: with contact (after SIM_POSITION)
#include "contact.glsl"
#endif

// Invocations of the workgroup (specialised)
const uint kInvocations = gl_WorkGroupSize.x;

// The barriers this invocation has passed in this dispatch (Counters::phases, what tender-bench
// counts: written once, at the end)
uint g_phases = 0u;

// Everything written before it, to shared memory and to buffers, is seen by the whole workgroup.
// The fence is the workgroup's (groupMemoryBarrier), not the device's: no other workgroup reads
// a sheet's arrays while it ticks (a fleet's workgroups tick a sheet each), and the next dispatch
// sees them through the pipeline barrier between.
void sync() {
  groupMemoryBarrier();
  barrier();
  g_phases += 1u;
}

// Diagnosis (`tender diff`): the tick stops after pass p.stop of the tick (the numbering of
// SIM_STAGES, sim_passes.h; SIM_NONE: it runs whole). Every invocation takes the same branch, after a barrier.
bool stopsAfter(uint pass) { return pass == p.stop; }

// The positions go back to their buffer (at the end of the dispatch, or where the tick stops).
void storePositions(uint n) {
  for (uint i = gl_LocalInvocationID.x; i < n; i += kInvocations) pos[i] = s_pos[i];
}

// Exclusive scan by the whole workgroup of cell_count into cell_start (SIM_SCAN_HASH) or of
// scratch[offset, offset + count) in place (SIM_SCAN_SCRATCH). Each invocation scans a contiguous
// chunk after adding up the totals of the chunks before its own, which meet in scratch[sums +
// invocation].
void scanWorkgroup(uint mode, uint offset, uint count, uint sums) {
  uint lid = gl_LocalInvocationID.x;
  uint chunk = (count + kInvocations - 1u) / kInvocations;
  uint first = min(lid * chunk, count), last = min(first + chunk, count);
  uint total = 0u;
  // (each array read only in its own mode: a fleet's arrays are not bounds-checked)
  if (mode == SIM_SCAN_HASH)
    for (uint k = first; k < last; ++k) total += cell_count[k];
  else
    for (uint k = first; k < last; ++k) total += scratch[offset + k];
  scratch[sums + lid] = total;
  sync();
  uint run = 0u;
  for (uint g = 0u; g < lid; ++g) run += scratch[sums + g];
  for (uint k = first; k < last; ++k) {
    if (mode == SIM_SCAN_HASH) {
      cell_start[k] = run;
      run += cell_count[k];
    } else {
      uint v = scratch[offset + k];
      scratch[offset + k] = run;
      run += v;
    }
  }
  sync();
}

#ifdef SIM_FUSED_CONTACT
// After the floor, with contact: each query's pairs from where the particles started, three
// times, then each step cut (as contact_pass, contact_excess, contact_share and contact_step); then,
// with the settle's sweeps on and an edge over the limit, the pairs' half-spaces counted by
// particle, scanned and listed, and the sweeps over the colours with structural edges until one
// moves nothing (as contact_settle_check, contact_half_count, scan, contact_half_fill and
// contact_settle). One loop over the five kinds of query, so that the shader holds one copy of
// contactNear's body here, not two (NIR inlines every call, and a copy is a fifth of the kernel).
// The settle's part runs with `settle` (stageRuns). True when the run stops after the floor
// (`floor_pass`: its first pass).
bool contactAfterFloor(uint s, uint n, uint floor_pass, bool settle) {
  uint lid = gl_LocalInvocationID.x;
  uint queries = u.particle_count + contactEdgeCount();
  for (uint only = NEAR_PASS; only <= NEAR_HALF_FILL; ++only) {
    if (only == NEAR_HALF_COUNT) {
      for (uint i = lid; i < n; i += kInvocations) {
        VerletState st;
        st.position = s_pos[i];
        st.previous = prev[i];
        st = contactSlideStep(i, st, s);
        s_pos[i] = st.position;
        prev[i] = st.previous;
      }
      sync();
      if (stopsAfter(floor_pass)) return true;
      if (!settle) return false;
      for (uint c = 0u; c < u.color_count; ++c) {
        uvec2 range = color_range[c];
        for (uint t = lid; t < range.y; t += kInvocations) contactSettleCheck(range.x + t, s);
      }
      sync();
      if (!settleStarts()) return false;
    }
    if (only == NEAR_HALF_FILL) scanWorkgroup(SIM_SCAN_SCRATCH, halfStarts(), u.particle_count + 1u, compactSlots());
    for (uint k = lid; k < queries; k += kInvocations) contactNear(k, only);
    sync();
  }
  for (uint sweep = 0u; sweep < contactChecks().sweeps; ++sweep) {
    for (uint c = 0u; c < u.color_count; ++c) {
      uvec2 range = color_range[c];
      if (range.y == 0u || !shortensColour(constraints[range.x].kind_id)) continue;
      for (uint t = lid; t < range.y; t += kInvocations) contactSettle(constraints[range.x + t], sweep, s);
      sync();
    }
    if (!settleSweeps(sweep + 1u)) break; // moved nothing: nor would the next
  }
  return false;
}

// Contact (as the contact_* passes, contact.glsl): each particle's step bound and push for substep
// s, from where it starts it.
void contactSubstep(uint s, uint n) {
  uint lid = gl_LocalInvocationID.x;
  sync(); // the positions of other invocations' particles
  if (lid == 0u) contactBegin(s, false);
  sync();
  uint slots = contactSlots(), boxes = u.triangle_count + contactEdgeCount();
  for (uint k = lid; k < slots; k += kInvocations) contactClear(k);
  sync();
  if (lid == 0u) contactTravelled();
  sync();
  for (uint k = lid; k < contactBucketSlots(); k += kInvocations) contactGridClear(k);
  sync();
  for (uint k = lid; k < boxes; k += kInvocations) contactInsert(k, false);
  sync();
  scanWorkgroup(SIM_SCAN_SCRATCH, contactCounts(), 2u * (contactGrid().mask + 1u) + 1u, compactSlots());
  for (uint k = lid; k < boxes; k += kInvocations) contactInsert(k, true);
  sync();
  for (uint t = lid; t < u.triangle_count; t += kInvocations) contactCross(t, s);
  sync();
  uint queries = u.particle_count + contactEdgeCount();
  for (uint k = lid; k < queries; k += kInvocations) contactNear(k, NEAR_ALL);
  sync();
  for (uint i = lid; i < n; i += kInvocations) contactBound(i, s);
  sync();
}

#endif

#ifdef SIM_BATCH
// One frame of the animated reset (as reset.comp), in the first dispatch of the sheet's tick.
void resetFrame(uint n) {
  if (p.first_substep != 0u) return;
  for (uint i = gl_LocalInvocationID.x; i < n; i += kInvocations) {
    float w = inverseMass(rest_pos[i], false, u.flags);
    vec4 q = vec4(blend3(vec3(reset_from[i]), vec3(rest_pos[i]), u.reset_alpha), w);
    pos[i] = q;
    prev[i] = q;
  }
}
#endif

// The air on each particle (as air.comp), which the integration reads
void airStage(uint n) {
  sync(); // the air reads the positions of other invocations' particles (loaded or moved)
  for (uint i = gl_LocalInvocationID.x; i < n; i += kInvocations) delta[i] = vec4(airOnParticle(i), 0.0f);
  sync();
}

// Verlet integration (as integrate.comp)
void integrateStage(uint s, uint n, float dt2) {
  uint lid = gl_LocalInvocationID.x;
  for (uint i = lid; i < n; i += kInvocations) {
    VerletState st = integrateParticle(i, s_pos[i], prev[i], rest_pos[i], uv[i].x, i == u.grab_index, u.grab_target[s],
                                       u.grab_prev[s], u.hand, u.hand_motion, u.flags, u.gravity,
                                       windWithAir(u.wind[s], delta[i], u.flags), u.wind_twist[s],
                                       substepDamping(u.damping, u.verlet, s), dt2);
    s_pos[i] = st.position;
    prev[i] = st.previous;
  }
  sync();
}

// Collision (as candidates_check, hash_*, collide and candidates_finish). From the candidate lists
// while they hold every pair that can touch (no particle has travelled SIM_CANDIDATE_TRAVEL x skin
// since they were built); otherwise from the spatial hash (count, scan, scatter, order within
// bucket) and a search of the 27 cells around each particle, which rebuilds the lists as it
// goes unless they were outgrown too fast of late (SIM_CANDIDATE_MIN_AGE, SIM_CANDIDATE_WAIT).
void collideStage(uint n) {
  uint lid = gl_LocalInvocationID.x;
  uvec4 state = counters.candidate_state;
  if (lid == 0u) counters.candidate_flags = uvec4(0u);
  sync();
  if (candidatesCurrentNow(state)) {
    float skin = candidateSkinNow();
    bool far = false;
    for (uint i = lid; i < n; i += kInvocations)
      far = far || travelledTooFar(vec3(s_pos[i]), vec3(candidate_base[i]), skin);
    if (far) atomicOr(counters.candidate_flags.x, 1u);
    sync();
  }
  uvec4 flags = counters.candidate_flags; // whole: no invocation sets one until the next sync
  uint mode = collideModeOf(state, flags.x != 0u);
  if (mode != SIM_COLLIDE_CANDIDATES) {
    for (uint i = lid; i < n; i += kInvocations) hashCount(i, vec3(s_pos[i]));
    sync();
    scanWorkgroup(SIM_SCAN_HASH, 0u, u.hash_mask + 1u, compactSlots());
    for (uint i = lid; i < n; i += kInvocations) hashScatter(i);
    sync();
    for (uint i = lid; i < n; i += kInvocations) hashSort(i, vec3(s_pos[i]));
    sync();
  } else {
    // The lists read the positions of other particles: all of them before any moves
    for (uint i = lid; i < n; i += kInvocations) delta[i] = vec4(candidateRepulsion(i, vec3(s_pos[i])), 0.0f);
    sync();
  }
  // Each free particle takes its repulsion (from the lists, or gathered here from the hash's
  // bucket-ordered copy of the positions; as collide.comp, then repel.comp), kept in delta too.
  for (uint i = lid; i < n; i += kInvocations) {
    vec4 q = s_pos[i];
    bool fits = true;
    vec3 repel = mode == SIM_COLLIDE_CANDIDATES ? vec3(delta[i]) : gatherParticle(i, vec3(q), mode, fits);
    if (!fits) atomicOr(counters.candidate_flags.y, 1u);
    delta[i] = vec4(repel, 0.0f);
    s_pos[i] = repelParticle(q, repel, u.flags);
  }
  sync();
  if (lid == 0u) {
    uvec4 after = counters.candidate_flags;
    counters.candidate_state = candidatesNextStateOf(state, mode, after.y != 0u);
  }
}

// Gauss-Seidel over colours (as project.comp), a barrier after each colour that projects in this
// iteration (projectsInIteration: the same for every invocation); with `shorten`, the shorten stage
// (as shorten.comp): the colours with edges. True when the run stops after one of the passes
// (numbered from `first`).
bool colourStage(bool shorten, uint first) {
  uint lid = gl_LocalInvocationID.x;
  for (uint it = 0u; it < u.iterations; ++it)
    for (uint c = 0u; c < u.color_count; ++c) {
      uvec2 range = color_range[c];
      uint kind = range.y > 0u ? constraints[range.x].kind_id : 0u;
      if (range.y > 0u && (shorten ? shortensColour(kind) : projectsInIteration(kind, it))) {
        // A colour is one kind: each kind's loop holds its body alone (project.comp, project_hinge.comp)
        if (shorten)
          for (uint t = lid; t < range.y; t += kInvocations) shortenConstraint(constraints[range.x + t]);
        else if ((kind & SIM_KIND_MASK) == SIM_KIND_HINGE)
          for (uint t = lid; t < range.y; t += kInvocations) projectHingeConstraint(constraints[range.x + t]);
        else
          for (uint t = lid; t < range.y; t += kInvocations) projectDistance(constraints[range.x + t]);
        sync();
      }
      if (stopsAfter(first + it * u.color_count + c)) return true;
    }
  return false;
}

// The stretch limit (as limit.comp): ring after ring from the roots
void limitStage() {
  uvec4 roots = limitRootSet(u.limit_roots, u.grab_index, u.cols, u.rows);
  LimitKeys limit = u.limit; // read whole (limitParticle says why)
  uint rings = uint(limit.last_ring);
  for (uint k = 1u; k <= rings; ++k) {
    limitRing(roots, k, gl_LocalInvocationID.x, kInvocations);
    sync();
  }
}

// The creases (as crease.comp)
void creaseStage() {
  for (uint k = gl_LocalInvocationID.x; k < hingeKeys().count; k += kInvocations) creaseHinge(k);
  sync();
}

// The floor (as floor.comp); with contact, the steps are then cut (contactAfterFloor)
void floorStage(uint n, bool contact) {
  uint lid = gl_LocalInvocationID.x;
  for (uint i = lid; i < n; i += kInvocations) {
    VerletState st = floorContact(s_pos[i], prev[i], u.floor_y, u.restitution, u.friction);
#ifdef SIM_FUSED_CONTACT
    if (contact) contactSlideClear(i);
#endif
    s_pos[i] = st.position;
    prev[i] = st.previous;
  }
  sync();
}

// Tear marking (as tear_mark.comp, which also visits the stale slots past each colour's live
// count: those mark nothing); when something tore, the compaction (as tear_flags, scan,
// tear_compact) in the same workgroup. A live constraint is never torn (the compaction of the
// substep it tore in removed it), and kinds that cannot tear skip the position loads.
void tearStage() {
  uint lid = gl_LocalInvocationID.x;
  for (uint c = 0u; c < u.color_count; ++c) {
    uvec2 range = color_range[c];
    for (uint t = lid; t < range.y; t += kInvocations) {
      Constraint k = constraints[range.x + t];
      if ((u.tear_kinds & (1u << (k.kind_id & SIM_KIND_MASK))) != 0u) markTear(k, s_pos[k.a], s_pos[k.b]);
    }
  }
  sync();
  if (counters.torn_new == 0u) return;
  // What stood on the triangles lost goes too (as tear_unsupported), then the compaction
  for (uint c = 0u; c < u.color_count; ++c) {
    uvec2 range = color_range[c];
    for (uint t = lid; t < range.y; t += kInvocations) markUnsupported(constraints[range.x + t]);
  }
  sync();
  uint slots = compactSlots();
  for (uint k = lid; k < slots; k += kInvocations) tearFlags(k);
  sync();
  scanWorkgroup(SIM_SCAN_SCRATCH, 0u, slots, slots);
  for (uint k = lid; k < slots; k += kInvocations) tearCompact(k);
  sync();
}

// The stages of each substep of this dispatch, those whose conditions hold (stageRuns), stopping
// where the run is cut short (stopsAfter: each stage's first pass by SIM_STAGES).
bool runSubsteps(uint n) {
  uint when = conditionsNow();
  bool tearing = tearingOn(u.tear_factor) && u.constraint_count > 0u;
  float dt2 = u.dt * u.dt;
  uint end = min(p.first_substep + p.substeps, substepCount(u.substeps));
  uint per_substep = passesPerSubstep(u.iterations, u.color_count, when);
#define SIM_RUNS(stage) stageRuns(SIM_STAGE_##stage, when)
  for (uint s = p.first_substep; s < end; ++s) {
#define SIM_FIRST_PASS(stage) (s * per_substep + stageFirstPass(SIM_STAGE_##stage, u.iterations, u.color_count, when))
#ifdef SIM_FUSED_CONTACT
    if (SIM_RUNS(contact)) {
      contactSubstep(s, n);
      if (stopsAfter(SIM_FIRST_PASS(contact))) return true;
    }
#endif
    if (SIM_RUNS(air)) {
      airStage(n);
      if (stopsAfter(SIM_FIRST_PASS(air))) return true;
    }
    integrateStage(s, n, dt2);
    if (stopsAfter(SIM_FIRST_PASS(integrate))) return true;
    // A new substep: no constraint torn in it yet (every invocation read the count of the last
    // substep before the barrier above).
    if (gl_LocalInvocationID.x == 0u) counters.torn_new = 0u;
    if (SIM_RUNS(collide)) {
      collideStage(n);
      if (stopsAfter(SIM_FIRST_PASS(collide))) return true;
    }
    if (colourStage(false, SIM_FIRST_PASS(project))) return true;
    if (SIM_RUNS(shorten) && colourStage(true, SIM_FIRST_PASS(shorten))) return true;
    if (SIM_RUNS(limit)) {
      limitStage();
      if (stopsAfter(SIM_FIRST_PASS(limit))) return true;
    }
    bool contact = runsWhen(SIM_WHEN_CONTACT, when);
    floorStage(n, contact);
#ifdef SIM_FUSED_CONTACT
    // With contact: the steps cut, then the settle stage (its sweeps on) in the same loop
    if (contact && contactAfterFloor(s, n, SIM_FIRST_PASS(floor), SIM_RUNS(settle))) return true;
    if (!contact && stopsAfter(SIM_FIRST_PASS(floor))) return true;
#else
    if (stopsAfter(SIM_FIRST_PASS(floor))) return true;
#endif
    if (SIM_RUNS(settle) && stopsAfter(SIM_FIRST_PASS(settle))) return true;
    if (SIM_RUNS(crease)) {
      creaseStage();
      if (stopsAfter(SIM_FIRST_PASS(crease))) return true;
    }
    if (tearing) tearStage();
    if (stopsAfter(SIM_FIRST_PASS(tear))) return true;
#undef SIM_FIRST_PASS
  }
#undef SIM_RUNS
  return false;
}

void main() {
  uint lid = gl_LocalInvocationID.x;
#ifdef SIM_BATCH
  bindSheet(batchSheet(groupIndex()));
  if (u.reset_active != 0u) {
    resetFrame(p.count);
    return;
  }
#endif
  uint n = p.count;
  for (uint i = lid; i < n; i += kInvocations) s_pos[i] = pos[i];
  runSubsteps(n);
  storePositions(n);
  // A tick's barriers: this dispatch's, after those of its earlier substeps' (a CPU device)
  if (lid == 0u) counters.phases = (p.first_substep == 0u ? 0u : counters.phases) + g_phases;
}
