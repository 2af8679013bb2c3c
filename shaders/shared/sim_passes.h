// The passes of the simulation: one table each for its kernels, the stages of a substep and the
// dispatches of each stage, read by GLSL, C++ and CMake alike. What runs, in which order, how it
// is numbered, gated and timed is derived from these rows:
//   SIM_KERNELS    the pipelines (SimPipelines' members, makePassPipelines) and the kernels a fleet
//                  also builds batched (shaders/CMakeLists.txt reads the rows)
//   SIM_STAGES     the numbered passes of a substep: `tender diff` and a tick cut short
//                  (core/passes.h), the CPU tick's order (CpuSolver::tick), the fused tick's pass
//                  numbers (fused_tick.glsl)
//   SIM_DISPATCHES what the per-colour path records for each stage (gpu/substep_passes.cpp): the
//                  sheet's solver and a fleet alike
// Keep one row per line, as written. A new pass is a row here, its shader and its shared body:
// docs/ARCHITECTURE.md §3a has the recipe.
#ifndef SIM_PASSES_H
#define SIM_PASSES_H
#include "prelude.h"
#include "sim_config.h"
#include "sim_types.h"

// The per-colour kernels, in the order a substep dispatches them (normals runs once a frame,
// reset during the animated reset).
// X(name, push, per_invocation, batched)
//   name            shaders/sim/<name>.comp.glsl, SimPipelines::<name>
//   push            its push constants: SIM (SimPush), SCAN (ScanPush) or NONE
//   per_invocation  elements one invocation covers
//   batched         1: a fleet runs it once for the whole batch (built again with SIM_BATCH_PASS)
#define SIM_KERNELS(X)                                                                                                 \
  X(contact_begin, SIM, 1, 1)                                                                                          \
  X(contact_clear, SIM, 1, 1)                                                                                          \
  X(contact_arm, SIM, 1, 1)                                                                                            \
  X(contact_grid_clear, SIM, 1, 1)                                                                                     \
  X(contact_count, SIM, 1, 1)                                                                                          \
  X(contact_scatter, SIM, 1, 1)                                                                                        \
  X(contact_cross, SIM, 1, 1)                                                                                          \
  X(contact_near, SIM, 1, 1)                                                                                           \
  X(contact_active, SIM, 1, 1)                                                                                         \
  X(contact_emit, SIM, 1, 1)                                                                                           \
  X(contact_walk, SIM, 1, 1)                                                                                           \
  X(contact_bound, SIM, 1, 1)                                                                                          \
  X(air, SIM, 1, 1)                                                                                                    \
  X(integrate, SIM, 1, 1)                                                                                              \
  X(candidates_check, SIM, 1, 1)                                                                                       \
  X(candidates_decide, SIM, 1, 1)                                                                                      \
  X(hash_count, SIM, 1, 1)                                                                                             \
  X(scan, SCAN, SIM_SCAN_PER_THREAD, 1)                                                                                \
  X(scan_add, SCAN, 1, 1)                                                                                              \
  X(hash_scatter, SIM, 1, 1)                                                                                           \
  X(hash_sort, SIM, 1, 1)                                                                                              \
  X(collide, SIM, 1, 1)                                                                                                \
  X(candidates_finish, SIM, 1, 1)                                                                                      \
  X(repel, SIM, 1, 1)                                                                                                  \
  X(project, SIM, 1, 1)                                                                                                \
  X(project_hinge, SIM, 1, 1)                                                                                          \
  X(shorten, SIM, 1, 1)                                                                                                \
  X(limit, SIM, 1, 1)                                                                                                  \
  X(crease, SIM, 1, 1)                                                                                                 \
  X(floor, SIM, 1, 1)                                                                                                  \
  X(contact_pass, SIM, 1, 1)                                                                                           \
  X(contact_excess, SIM, 1, 1)                                                                                         \
  X(contact_share, SIM, 1, 1)                                                                                          \
  X(contact_step, SIM, 1, 1)                                                                                           \
  X(contact_settle_check, SIM, 1, 1)                                                                                   \
  X(contact_half_count, SIM, 1, 1)                                                                                     \
  X(contact_half_fill, SIM, 1, 1)                                                                                      \
  X(contact_settle, SIM, 1, 1)                                                                                         \
  X(tear_mark, SIM, 1, 1)                                                                                              \
  X(tear_unsupported, NONE, 1, 1)                                                                                      \
  X(tear_flags, NONE, 1, 1)                                                                                            \
  X(tear_compact, NONE, 1, 1)                                                                                          \
  X(normals, SIM, 1, 0)                                                                                                \
  X(reset, SIM, 1, 1)

// When a stage or a dispatch runs: the conditions of a sheet's uniforms it needs, as bits
// (stageConditions gathers them; 0: always).
#define SIM_WHEN_ALWAYS 0u
// collision is on (SIM_FLAG_COLLISION)
#define SIM_WHEN_COLLISION 1u
// the sheet has air (SIM_FLAG_AIR)
#define SIM_WHEN_AIR 2u
// contact is on (SimUniforms::contact.radius, the contact radius)
#define SIM_WHEN_CONTACT 4u
// the stretch limit is on (SimUniforms::limit.reach)
#define SIM_WHEN_LIMIT 8u
// the limit shortens edges first: nothing holds the sheet (no grab, no pins)
#define SIM_WHEN_SHORTEN 16u
// the sheet has hinges and they crease (a yield angle)
#define SIM_WHEN_CREASE 32u
// contact is on with the settle's sweeps (SimUniforms::contact_check.sweeps)
#define SIM_WHEN_SETTLE 64u

// The stages of a substep, in the order they run; each is one numbered pass, or one per colour of
// each iteration, while its condition holds (none otherwise). A tick numbers its passes substep x
// passesPerSubstep + the pass within the substep.
// X(name, id, repeat, when)
//   name    what `tender diff` and TENDER_TEST_PLANT_ULP call it; PassKind::<name> in C++
//   id      its place in this table (0u, 1u, ...); SIM_STAGE_<name>
//   repeat  ONCE, or COLOUR: once per colour of each iteration
//   when    SIM_WHEN_<when>: what it runs under (stageRuns)
#define SIM_STAGES(X)                                                                                                  \
  X(contact, 0u, ONCE, CONTACT)                                                                                        \
  X(air, 1u, ONCE, AIR)                                                                                                \
  X(integrate, 2u, ONCE, ALWAYS)                                                                                       \
  X(collide, 3u, ONCE, COLLISION)                                                                                      \
  X(project, 4u, COLOUR, ALWAYS)                                                                                       \
  X(shorten, 5u, COLOUR, SHORTEN)                                                                                      \
  X(limit, 6u, ONCE, LIMIT)                                                                                            \
  X(floor, 7u, ONCE, ALWAYS)                                                                                           \
  X(settle, 8u, ONCE, SETTLE)                                                                                          \
  X(crease, 9u, ONCE, CREASE)                                                                                          \
  X(tear, 10u, ONCE, ALWAYS)
#define SIM_STAGE_COUNT 11u

// The dispatches of each stage, in the order the per-colour path records them (a barrier after
// each). The fused tick and the CPU run the same bodies in the same order.
// X(stage, kernel, elements, grid, when, category)
//   stage     its row in SIM_STAGES
//   kernel    its row in SIM_KERNELS (scan: a scan of several blocks adds scan and scan_add)
//   elements  what it covers and its push constants: PARTICLES, COLOUR (the stage's colour, unless
//             it holds hinges), HINGE_COLOUR (the stage's colour when it holds hinges),
//             HINGES, CONSTRAINTS, ONE (one invocation), HASH_ARGS (one invocation, the hash's
//             arguments), RINGS (one workgroup a sheet, a dispatch for each limitRingsPerDispatch
//             rings of the stretch limit), HASH_CELLS and TEAR_SLOTS (a scan of the hash's cells or of the
//             compaction's slots), INDIRECT (the grid's arguments, no push constants); contact's:
//             TRIANGLES (the triangle slots), CONTACT_SLOTS (whatever its clearing covers),
//             CONTACT_BUCKETS (its grid's buckets and their end),
//             CONTACT_BOXES (triangle slots, then edges), CONTACT_QUERIES (particles, then
//             edges), CONTACT_CELLS (a scan of its grid's buckets), CONTACT_ACTIVE (the queries
//             and their end, from the scratch offset of their flags) and CONTACT_ACTIVE_CELLS (a
//             scan of those flags); the settle's: CONTACT_HALF_CELLS (a scan of the particles'
//             half-space counts) and SWEEPS (the colours with structural edges, once each sweep:
//             SimPush.first the sweep)
//   grid      Threads (from the elements), Hash (the live hash arguments candidates_decide
//             copies), Contact (the live arguments of contact's grid passes contact_arm copies:
//             none in a substep that does not build the grid), Walk (contact_walk's, over the
//             queries with pairs in their lists: none in a substep that builds them), Cross
//             (contact_cross's, over the triangles: none in a substep whose crossing check looks
//             at no triangle), Named (contact_emit's: the queries with pairs in their lists),
//             Settle (the settle's half-spaces' passes: the named queries' grid, none in a substep
//             with no edge over the limit), Sweep (a settle sweep's, each colour's grid that of the largest:
//             none after a sweep that moved nothing) or
//             Compaction (the tear compaction's arguments): gpu::Grid. A fleet's sheet takes an
//             indirect pass when its own arguments would have given it workgroups (liveGate).
//   when      SIM_WHEN_<when>: what it needs besides its stage's condition
//   category  its timestamp category (gpu::PassCategory k<category>)
#define SIM_DISPATCHES(X)                                                                                              \
  X(contact, contact_begin, ONE, Threads, ALWAYS, Contact)                                                             \
  X(contact, contact_clear, CONTACT_SLOTS, Threads, ALWAYS, Contact)                                                   \
  X(contact, contact_arm, ONE, Threads, ALWAYS, Contact)                                                               \
  X(contact, contact_grid_clear, CONTACT_BUCKETS, Contact, ALWAYS, Contact)                                            \
  X(contact, contact_count, CONTACT_BOXES, Contact, ALWAYS, Contact)                                                   \
  X(contact, scan, CONTACT_CELLS, Contact, ALWAYS, Contact)                                                            \
  X(contact, contact_scatter, CONTACT_BOXES, Contact, ALWAYS, Contact)                                                 \
  X(contact, contact_cross, TRIANGLES, Cross, ALWAYS, Contact)                                                         \
  X(contact, contact_near, CONTACT_QUERIES, Contact, ALWAYS, Contact)                                                  \
  X(contact, contact_active, CONTACT_ACTIVE, Contact, ALWAYS, Contact)                                                 \
  X(contact, scan, CONTACT_ACTIVE_CELLS, Contact, ALWAYS, Contact)                                                     \
  X(contact, contact_emit, CONTACT_ACTIVE, Contact, ALWAYS, Contact)                                                   \
  X(contact, contact_walk, CONTACT_QUERIES, Walk, ALWAYS, Contact)                                                     \
  X(contact, contact_bound, PARTICLES, Threads, ALWAYS, Contact)                                                       \
  X(air, air, PARTICLES, Threads, ALWAYS, Integrate)                                                                   \
  X(integrate, integrate, PARTICLES, Threads, ALWAYS, Integrate)                                                       \
  X(collide, candidates_check, PARTICLES, Threads, ALWAYS, Hash)                                                       \
  X(collide, candidates_decide, HASH_ARGS, Threads, ALWAYS, Hash)                                                      \
  X(collide, hash_count, PARTICLES, Hash, ALWAYS, Hash)                                                                \
  X(collide, scan, HASH_CELLS, Hash, ALWAYS, Hash)                                                                     \
  X(collide, hash_scatter, PARTICLES, Hash, ALWAYS, Hash)                                                              \
  X(collide, hash_sort, PARTICLES, Hash, ALWAYS, Hash)                                                                 \
  X(collide, collide, PARTICLES, Threads, ALWAYS, Collide)                                                             \
  X(collide, candidates_finish, ONE, Threads, ALWAYS, Collide)                                                         \
  X(collide, repel, PARTICLES, Threads, ALWAYS, Collide)                                                               \
  X(project, project, COLOUR, Threads, ALWAYS, Project)                                                                \
  X(project, project_hinge, HINGE_COLOUR, Threads, ALWAYS, Project)                                                    \
  X(shorten, shorten, COLOUR, Threads, ALWAYS, Project)                                                                \
  X(limit, limit, RINGS, Threads, ALWAYS, Project)                                                                     \
  X(floor, floor, PARTICLES, Threads, ALWAYS, Floor)                                                                   \
  X(floor, contact_pass, CONTACT_QUERIES, Named, CONTACT, Floor)                                                       \
  X(floor, contact_excess, CONTACT_QUERIES, Named, CONTACT, Floor)                                                     \
  X(floor, contact_share, CONTACT_QUERIES, Named, CONTACT, Floor)                                                      \
  X(floor, contact_step, PARTICLES, Threads, CONTACT, Floor)                                                           \
  X(settle, contact_settle_check, CONSTRAINTS, Threads, ALWAYS, Floor)                                                 \
  X(settle, contact_half_count, CONTACT_QUERIES, Settle, ALWAYS, Floor)                                                \
  X(settle, scan, CONTACT_HALF_CELLS, Threads, ALWAYS, Floor)                                                          \
  X(settle, contact_half_fill, CONTACT_QUERIES, Settle, ALWAYS, Floor)                                                 \
  X(settle, contact_settle, SWEEPS, Sweep, ALWAYS, Floor)                                                              \
  X(crease, crease, HINGES, Threads, ALWAYS, Project)                                                                  \
  X(tear, tear_mark, CONSTRAINTS, Threads, ALWAYS, Tear)                                                               \
  X(tear, tear_unsupported, INDIRECT, Compaction, ALWAYS, Tear)                                                        \
  X(tear, tear_flags, INDIRECT, Compaction, ALWAYS, Tear)                                                              \
  X(tear, scan, TEAR_SLOTS, Compaction, ALWAYS, Tear)                                                                  \
  X(tear, tear_compact, INDIRECT, Compaction, ALWAYS, Tear)

#define SIM_STAGE_ID(name, id, repeat, when) SIM_CONST uint SIM_STAGE_##name = id;
SIM_STAGES(SIM_STAGE_ID)
#undef SIM_STAGE_ID

/// True when the stretch limit first shortens the sheet's edges from both ends (the shorten stage)
/// before its rings: nothing holds the sheet (no grab, no pins). The rings alone draw the sheet
/// after their root, one-sidedly, and with no hand or pin to root them at, the free middle they
/// root at keeps a crumpled ball moving: 1.8 to 3.5 units/s 8 s after a fast crumple
/// (`bench/rest.py`, measured at 2bf6ebd).
SIM_INLINE bool limitShortens(float reach, uint grab_index, uint flags) {
  return reach > 0.0f && grab_index == SIM_NONE && (flags & SIM_FLAG_PINS) == 0u;
}

/// True when a sheet of `hinges` hinges creases at this yield (creaseReturn; 0: elastic).
SIM_INLINE bool creasing(uint hinges, float yield0) { return hinges > 0u && yield0 > 0.0f; }

/// The conditions (SIM_WHEN_* bits) a sheet's uniforms meet: its flags, the grabbed particle, its
/// hinges and their yield angle, the stretch limit's reach, the contact radius and the settle's
/// sweeps. What runs in a substep is decided here alone: the per-colour recorder, a fleet's gate,
/// the fused tick, the kernels and the CPU ask stageRuns and runsWhen with these.
SIM_INLINE uint stageConditions(uint flags, uint grab_index, uint hinges, float yield0, float reach, float contact,
                                uint sweeps) {
  uint when = SIM_WHEN_ALWAYS;
  if ((flags & SIM_FLAG_COLLISION) != 0u) when |= SIM_WHEN_COLLISION;
  if ((flags & SIM_FLAG_AIR) != 0u) when |= SIM_WHEN_AIR;
  if (contact > 0.0f) when |= SIM_WHEN_CONTACT;
  if (reach > 0.0f) when |= SIM_WHEN_LIMIT;
  if (limitShortens(reach, grab_index, flags)) when |= SIM_WHEN_SHORTEN;
  if (creasing(hinges, yield0)) when |= SIM_WHEN_CREASE;
  if (contact > 0.0f && sweeps > 0u) when |= SIM_WHEN_SETTLE;
  return when;
}

/// True when conditions `when` (stageConditions) meet all of `needs` (SIM_WHEN_* bits).
SIM_INLINE bool runsWhen(uint needs, uint when) { return (when & needs) == needs; }

/// What stage `stage` runs under (SIM_STAGES' when).
SIM_INLINE uint stageNeeds(uint stage) {
  uint needs = SIM_WHEN_ALWAYS;
#define SIM_STAGE_NEEDS(name, id, repeat, when)                                                                        \
  if (stage == id) needs = SIM_WHEN_##when;
  SIM_STAGES(SIM_STAGE_NEEDS)
#undef SIM_STAGE_NEEDS
  return needs;
}

/// True when stage `stage` runs under conditions `when`.
SIM_INLINE bool stageRuns(uint stage, uint when) { return runsWhen(stageNeeds(stage), when); }

// A stage's repeat as a value (stagePasses)
#define SIM_STAGE_REPEATS_ONCE false
#define SIM_STAGE_REPEATS_COLOUR true

/// Passes stage `stage` numbers in a substep of `iterations` x `colors` projections under
/// conditions `when` (0: it does not run).
SIM_INLINE uint stagePasses(uint stage, uint iterations, uint colors, uint when) {
  uint passes = 0u;
#define SIM_STAGE_PASSES(name, id, repeat, needs)                                                                      \
  if (stage == id && runsWhen(SIM_WHEN_##needs, when)) passes = SIM_STAGE_REPEATS_##repeat ? iterations * colors : 1u;
  SIM_STAGES(SIM_STAGE_PASSES)
#undef SIM_STAGE_PASSES
  return passes;
}

/// Number within its substep of the first pass of stage `stage` (of SIM_STAGE_COUNT: the passes of
/// a substep).
SIM_INLINE uint stageFirstPass(uint stage, uint iterations, uint colors, uint when) {
  uint first = 0u;
  for (uint k = 0u; k < stage; ++k) first += stagePasses(k, iterations, colors, when);
  return first;
}

/// The grid of `groups` workgroups: at most SIM_MAX_GROUPS_X in x, the rest spilled into y (the
/// shaders linearise the group index, threadIndex in sim_common.glsl).
SIM_INLINE uvec2 groupGrid(uint groups) {
  uint gx = min(groups, uint(SIM_MAX_GROUPS_X));
  return uvec2(gx, gx > 0u ? (groups + gx - 1u) / gx : 0u);
}

/// Passes one substep numbers.
SIM_INLINE uint passesPerSubstep(uint iterations, uint colors, uint when) {
  return stageFirstPass(SIM_STAGE_COUNT, iterations, colors, when);
}
#endif
