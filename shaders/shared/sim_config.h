// Compile-time knobs shared by the shaders and the C++ side.
#ifndef SIM_CONFIG_H
#define SIM_CONFIG_H

// Workgroup size for per-particle passes (integrate, floor, normals, hash, pick)
#define SIM_WG_PARTICLES 64
// Workgroup size for constraint projection (one thread per constraint of a colour)
#define SIM_WG_PROJECT 64
// Workgroup size for collision gathering (one thread per particle)
#define SIM_WG_COLLIDE 64
// Workgroup size for tear marking and compaction (one thread per constraint or triangle)
#define SIM_WG_TEAR 64
// Workgroup size of the stretch limit: one workgroup a sheet walks its rings (limit.comp;
// specialization constant 0). On a CPU device one subgroup (lavapipe's: 8 lanes of AVX2), as it
// runs each further subgroup of a workgroup as a coroutine that every barrier switches through
// (with 64, the rings were a third of the project passes' time on lavapipe); on a GPU as many as a
// ring of a 1024-wide sheet has slots (limitSlots: 2 x the shorter side), so that a ring is one
// round of loads and stores: with 64, each of a 512 x 768 sheet's 16 rounds a ring waits on device
// memory (an H100: 395 ms a tick of the crumple preset)
#define SIM_WG_LIMIT 8
#define SIM_WG_LIMIT_GPU 1024
// Loop iterations one invocation of the stretch limit runs in a dispatch at most (rings, and the
// slots of each): lavapipe ends every loop of a shader after 65535 in all (LP_MAX_TGSI_LOOP_ITERATIONS,
// bench/README.md), so a large sheet's rings take several dispatches (limitRingsPerDispatch)
#define SIM_LIMIT_LOOP_BUDGET 16384u
// Roots the stretch limit runs from at most (SimUniforms::limit_roots: a sheet's pins)
#define SIM_LIMIT_ROOTS 3u
// Workgroup size of the block scan; each thread scans SIM_SCAN_PER_THREAD elements
#define SIM_WG_SCAN 256
// Elements scanned per thread in the block scan
#define SIM_SCAN_PER_THREAD 4
// Specialization constants of every simulation shader (see exact_math.h): emulate an inexact
// device's sqrt and divide; correct them (off only to show what the correction is for)
#define SIM_SPEC_INEXACT_MATH 1
#define SIM_SPEC_CORRECT_MATH 2
#define SIM_SPEC_FLUSH_DENORMALS 3
// ... and the particles the fused tick holds in shared memory (fusedCapacity in sim_pipeline.h)
#define SIM_SPEC_FUSED_CAPACITY 4
// Largest number of substeps per tick (per-substep inputs are arrays of this size)
#define SIM_MAX_SUBSTEPS 32
// Largest number of constraint colours
#define SIM_MAX_COLORS 64
// Frames the animated reset takes to bring the sheet back to its start
#define SIM_RESET_FRAMES 30
// Sentinel particle index: nothing grabbed, nothing picked
#define SIM_NONE 0xFFFFFFFFu

// Constraint kinds (low three bits of Constraint.kind_id; the original id sits above them). A
// hinge is the signed dihedral angle between the two triangles of an interior edge: its a and b
// are the corners opposite the edge, the edge itself follows from the grid (gridHinge in xpbd.h)
#define SIM_KIND_STRUCTURAL 0u
#define SIM_KIND_SHEAR 1u
#define SIM_KIND_BEND 2u
#define SIM_KIND_TRIBEND 3u
#define SIM_KIND_HINGE 4u
#define SIM_KIND_COUNT 5u
#define SIM_KIND_BITS 3u
#define SIM_KIND_MASK 7u

// Descriptor bindings of the simulation set (one set, shared by every sim pass)
#define SIM_BIND_UNIFORMS 0
#define SIM_BIND_POS 1
#define SIM_BIND_PREV 2
#define SIM_BIND_REST 3
#define SIM_BIND_UV 4
#define SIM_BIND_NORMAL 5
#define SIM_BIND_CONSTRAINTS 6
#define SIM_BIND_COLOR_RANGES 7
#define SIM_BIND_ADJ_OFFSETS 8
#define SIM_BIND_ADJ_LIST 9
#define SIM_BIND_CELL_COUNT 10
#define SIM_BIND_CELL_START 11
#define SIM_BIND_CELL_PARTICLES 12
#define SIM_BIND_PARTICLE_CELL 13
#define SIM_BIND_DELTA 14
#define SIM_BIND_TORN 15
#define SIM_BIND_TRIANGLES 16
#define SIM_BIND_TRI_EDGES 17
#define SIM_BIND_COUNTERS 18
#define SIM_BIND_SCRATCH 19
#define SIM_BIND_PICK 20
#define SIM_BIND_RESET_FROM 21
#define SIM_BIND_CELL_SCATTER 22
#define SIM_BIND_COMPACT_TMP 23
#define SIM_BIND_CELL_POS 24
#define SIM_BIND_ADJ_MASK 25
#define SIM_BIND_CANDIDATES 26
#define SIM_BIND_CANDIDATE_BASE 27
#define SIM_BIND_HASH_ARGS 28
// Per hinge (HingeState): its plastic rest angle, the yield its hardening added, its XPBD multiplier
#define SIM_BIND_HINGES 29
// Penetration-free contact (contact.h, the contact_* passes), in words: the sheet's edges, each once
// (four words: its particles a < b, then the ids of the one or two triangles that hold it, SIM_NONE
// for none), sorted by (a, b); then the pair lists (contact_grid.glsl): SIM_CONTACT_LIST_HEADER words
// (the triangle count they stand for, the radius, the builds, whether a query searches, the build
// whose queries are named: contact_grid.glsl's LIST_*), where each particle was when they
// were built (four words each), and per query (particles, then edges) the count of its pairs and
// SIM_CONTACT_LIST_CAPACITY slots for them
#define SIM_BIND_CONTACT_LISTS 30
// Per particle (ContactParticle): where it starts the substep, its bound and push, its nearest
// distance and whether it is free, its pushes and passed steps in fixed point
#define SIM_BIND_CONTACT 31
// The contact grid's words: SIM_CONTACT_HEADER words (ContactHeader), then the grid's entries
// (SIM_CONTACT_CELLS_PER_BOX per triangle and edge at most) and the boxes
#define SIM_BIND_CONTACT_GRID 32
// A fleet's shaders (tick_batch.comp, and the per-colour passes built with SIM_BATCH_PASS) reach
// each binding's buffer through its device address instead: the fleet's table (BatchArgs.table)
// holds, per binding (SIM_BIND_*; the uniforms are one SimUniforms per sheet), the address of sheet
// 0's slice and the bytes from one sheet's slice to the next, then at SIM_BATCH_QUEUE the list of
// sheets to tick (one per workgroup of tick_batch, one per workgroup z of a pass)
#define SIM_BATCH_QUEUE 33
// ... and at SIM_BATCH_ARGS the indirect arguments of the per-colour passes of a batch (uvec4 each,
// workgroup counts x, y and z = the batch's sheets): the full grids of the hash passes (a slot per
// pass, as SIM_BIND_HASH_ARGS) and of the compaction, which the host writes, then per substep the
// live ones, which the host writes with x = 0 and a sheet's candidates_decide (hash) or tear_mark
// (compaction) raises to the full grid's x when that sheet needs them: a pass that no sheet of the
// batch needs runs zero workgroups, as it does for a sheet alone
#define SIM_BATCH_ARGS 34
// Entries of the fleet's table
#define SIM_BATCH_ENTRIES 35
// Contact's passes alike: the full grids of its grid's passes, then per substep the live ones of
// its grid's passes (contact_arm raises them to the full grid's x when a sheet builds its grid),
// of contact_walk, of contact_cross and of the named queries (Grid::Named; each sheet raises them to
// its own grid's x and y, the named ones again when contact_emit names them anew)
#define SIM_BATCH_ARGS_FULL_COMPACT SIM_HASH_DISPATCHES
#define SIM_BATCH_ARGS_LIVE_HASH (SIM_BATCH_ARGS_FULL_COMPACT + 1u)
#define SIM_BATCH_ARGS_LIVE_COMPACT (SIM_BATCH_ARGS_LIVE_HASH + SIM_MAX_SUBSTEPS * SIM_HASH_DISPATCHES)
#define SIM_BATCH_ARGS_FULL_CONTACT (SIM_BATCH_ARGS_LIVE_COMPACT + SIM_MAX_SUBSTEPS)
#define SIM_BATCH_CONTACT_SLOTS (SIM_CONTACT_GRID_DISPATCHES + 3u)
#define SIM_BATCH_ARGS_LIVE_CONTACT (SIM_BATCH_ARGS_FULL_CONTACT + SIM_CONTACT_GRID_DISPATCHES)
// The settle stage's alike: a sweep's full grid, then per substep its live arguments (slots as in
// SIM_BIND_HASH_ARGS, SIM_CONTACT_SETTLE_ARGS; a sheet raises them where it would arm its own)
#define SIM_BATCH_ARGS_FULL_SETTLE (SIM_BATCH_ARGS_LIVE_CONTACT + SIM_MAX_SUBSTEPS * SIM_BATCH_CONTACT_SLOTS)
#define SIM_BATCH_ARGS_LIVE_SETTLE (SIM_BATCH_ARGS_FULL_SETTLE + 1u)
#define SIM_BATCH_ARGS_COUNT (SIM_BATCH_ARGS_LIVE_SETTLE + SIM_MAX_SUBSTEPS * SIM_CONTACT_SETTLE_SLOTS)
// Which sheets of a batch a per-colour pass runs for: those that tick (no animated reset), have
// the pass's substep and meet its conditions (BatchArgs.when: stageConditions, sim_passes.h), and
// of those the ones its run-time gate takes (BatchArgs.live). The batch records the passes of its
// most substeps and iterations, under the union of its sheets' conditions; a sheet runs a pass
// exactly when the same sheet ticking alone records or dispatches it.
// SIM_LIVE_NONE: no further condition
#define SIM_LIVE_NONE 0u
// SIM_LIVE_ITERATION: the sheet has iteration BatchArgs.arg (a colour's pass of project, shorten)
#define SIM_LIVE_ITERATION 1u
// SIM_LIVE_HASH: the sheet's lists do not stand in for the hash this substep (the hash passes,
// which alone run the grid candidates_decide gives them)
#define SIM_LIVE_HASH 2u
// SIM_LIVE_COMPACTION: something of the sheet tore this substep (the compaction passes, which
// alone run the grid tear_mark gives them)
#define SIM_LIVE_COMPACTION 3u
// SIM_LIVE_CONTACT_GRID: the sheet builds its contact grid this substep (contact_arm armed its
// grid's passes: they alone run the grid the batch's live arguments give them)
#define SIM_LIVE_CONTACT_GRID 4u
// SIM_LIVE_CONTACT_WALK, SIM_LIVE_CONTACT_CROSS: the sheet's own arguments of contact_walk
// (contact_cross) have workgroups this substep
#define SIM_LIVE_CONTACT_WALK 5u
#define SIM_LIVE_CONTACT_CROSS 6u
// SIM_LIVE_SWEEP: the sheet has settle sweep BatchArgs.arg
#define SIM_LIVE_SWEEP 7u
// SIM_LIVE_RESET: the sheet runs a frame of the animated reset (reset; no other condition)
#define SIM_LIVE_RESET 8u
// Sheets per hardware thread that one dispatch of a fleet takes on a CPU device, which runs a
// substep per dispatch: each thread keeps its sheet's arrays (under 1 MiB for 32 x 48) in its
// cache through every substep before the next sheets start (lavapipe, 2 threads, 64 sheets of
// 32 x 48: 425 ms per batched tick at 1 sheet per thread, 815 at 2, 972 with all in each dispatch)
#define SIM_BATCH_CPU_SHEETS_PER_THREAD 1

// Adjacency masks (SIM_BIND_ADJ_MASK): bit (dy + 2) * 5 + (dx + 2) is set when particle i is
// connected to the particle dx columns and dy rows away; SIM_ADJ_FAR when it is connected to a
// particle outside that 5 x 5 stencil (look those up in the adjacency list)
#define SIM_ADJ_STENCIL 2
#define SIM_ADJ_FAR 0x80000000u

// Elements one workgroup of the block scan covers
#define SIM_SCAN_BLOCK (SIM_WG_SCAN * SIM_SCAN_PER_THREAD)
// Workgroup size of the fused small-sheet tick on a GPU (every pass of every substep in one
// workgroup; specialization constant 0) for a sheet alone and for a fleet's sheets, and the
// largest it can be asked for (FusedShape; the device's limits may allow less). Measured on an
// H100 (bench/README.md, "On a GPU"): a 32 x 48 sheet alone ticks in 2.30 ms with 256 invocations,
// 1.79 with 512, 1.36 with 1024; a fleet of 1,024 of them in 22.3, 18.3 and 22.9 ms (a workgroup
// of 1,024 leaves an SM room for one sheet at a time, 512 for two)
#define SIM_WG_FUSED 1024
#define SIM_WG_FUSED_FLEET 512
#define SIM_WG_FUSED_MAX 1024
// Workgroup size of the fused tick on a CPU device: lavapipe runs a workgroup on one thread, its
// SIMD groups (8 invocations) taking turns at every barrier, and sets up each group's state at
// every dispatch, so fewer invocations pay less per barrier and per dispatch; but each group
// then runs more loop iterations (see SIM_FUSED_SUBSTEPS_CPU)
#define SIM_WG_FUSED_CPU 64
// Substeps one dispatch of the fused tick runs on a CPU device (on a GPU: the whole tick). Lavapipe
// ends every loop of a shader once one SIMD group has run 65535 loop iterations in total, all
// loops counted together (LP_MAX_TGSI_LOOP_ITERATIONS); a whole tick of a crumpled sheet in one
// workgroup can run that many, so each substep gets a dispatch, and a fresh count, of its own.
#define SIM_FUSED_SUBSTEPS_CPU 1
// Largest hash cell, in grid spacings, with which a CPU device runs the fused tick (with collision
// on). A SIMD group gathers the collisions of many particles one after the other, and a bucket of a
// flat sheet holds about (cell / spacing)^2 of them: bigger cells could use up lavapipe's loop
// count within one substep (the presets use 2.5; the per-colour passes stay within it at any size)
#define SIM_FUSED_CPU_MAX_CELL_SPACINGS 4.0f
// Largest sheet the fused tick takes on any device: it keeps the positions in shared memory (a
// vec4 each), so a device takes as many particles as its shared memory holds, up to this
// (SIM_SPEC_FUSED_CAPACITY: lavapipe's 32 KiB hold 2,048, NVIDIA's 48 KiB 3,072, 64 KiB 4,096).
// The hash table it scans every substep in one workgroup has at most twice as many buckets.
#define SIM_FUSED_MAX_PARTICLES 4096u

// Candidate lists of the fused tick (SIM_BIND_CANDIDATES): for each particle, the particles not
// connected to it within collision radius + skin when the lists were built (SIM_BIND_CANDIDATE_BASE
// holds the positions then). While no particle has moved SIM_CANDIDATE_TRAVEL x skin since, every pair
// closer than the radius is in the lists, so a substep reads the lists instead of rebuilding the
// hash and searching 27 cells. Record of particle i: SIM_CANDIDATE_STRIDE words at i * SIM_CANDIDATE_STRIDE,
// the count then up to SIM_CANDIDATE_CAPACITY particles in ascending order.
#define SIM_CANDIDATE_CAPACITY 15u
#define SIM_CANDIDATE_STRIDE 16u
// Skin: this fraction of the collision radius, at most 0.99 x (cell - radius), so that the lists
// come from the 27 cells around a particle; below SIM_CANDIDATE_MIN_SKIN x radius no lists are kept
#define SIM_CANDIDATE_SKIN 0.5f
#define SIM_CANDIDATE_MIN_SKIN 0.05f
// Lists are usable while every particle is within this fraction of the skin of where it was when
// they were built (two particles then closed in by less than the skin, with room for rounding)
#define SIM_CANDIDATE_TRAVEL 0.45f
// Lists outgrown within SIM_CANDIDATE_MIN_AGE substeps, or overflowing, are not rebuilt for
// SIM_CANDIDATE_WAIT substeps: fast motion (a drag, a toss) uses the hash every substep instead
#define SIM_CANDIDATE_MIN_AGE 4u
// How a substep finds its collisions: build the hash and search the 27 cells within the radius;
// sum from the candidate lists; or build the hash, search within radius + skin, build the lists
#define SIM_COLLIDE_HASH 0u
#define SIM_COLLIDE_CANDIDATES 1u
#define SIM_COLLIDE_BUILD 2u
#define SIM_CANDIDATE_WAIT 32u
// Indirect dispatches of the separate hash passes (SIM_BIND_HASH_ARGS holds this many live
// arguments, then as many with every pass's full grid): candidates_decide zeroes the live ones in a
// substep that sums from the lists
#define SIM_HASH_DISPATCHES 16u
// Indirect dispatches of contact's grid passes (Grid::Contact): SIM_BIND_HASH_ARGS holds, after
// the hash passes' arguments, this many live ones from SIM_CONTACT_GRID_ARGS, then as many with
// every pass's full grid; contact_arm zeroes the live ones in a substep that does not build the grid
#define SIM_CONTACT_GRID_DISPATCHES 24u
#define SIM_CONTACT_GRID_ARGS (2u * SIM_HASH_DISPATCHES)
// ... then contact_walk's live arguments (w: the queries it walks), then those contact_emit wrote at
// the last build of the lists (Grid::Named: every query with pairs in its list, which
// contact_pass, contact_excess and contact_share take; the walk those within their slots)
#define SIM_CONTACT_WALK_ARGS (SIM_CONTACT_GRID_ARGS + 2u * SIM_CONTACT_GRID_DISPATCHES)
// ... then contact_cross's live arguments (contact_arm: every triangle, or none)
#define SIM_CONTACT_CROSS_ARGS (SIM_CONTACT_WALK_ARGS + 2u)
// ... then the settle stage's live arguments (SIM_CONTACT_SETTLE_SLOTS): slot 0 its half-spaces'
// passes (Grid::Settle: the named queries' grid), slot 1 + k its sweep k (Grid::Sweep), none until
// contact_settle_check finds an edge over the limit (slots 0 and 1) or sweep k - 1 moves one (slot
// 1 + k); then a sweep's full grid (SIM_CONTACT_SETTLE_FULL)
#define SIM_CONTACT_SETTLE_ARGS (SIM_CONTACT_CROSS_ARGS + 1u)
#define SIM_CONTACT_SETTLE_SLOTS (SIM_SETTLE_MAX_SWEEPS + 1u)
#define SIM_CONTACT_SETTLE_FULL (SIM_CONTACT_SETTLE_ARGS + SIM_CONTACT_SETTLE_SLOTS)
// The uvec4 of SIM_BIND_HASH_ARGS
#define SIM_SHEET_ARGS (SIM_CONTACT_SETTLE_FULL + 1u)

// Penetration-free contact (contact.h): the part of the distance to its nearest primitive a particle
// may move in a substep; below 1/2, with room for rounding
#define SIM_CONTACT_FRACTION 0.4f
// The least distance of two primitives, per unit of contact radius: far above the rounding of the
// positions, so that the bound of a step (stepBound in contact.h) holds in floats
#define SIM_CONTACT_MARGIN 1e-3f
// The part of the distance to its nearest primitive, less half the margin, the push may move a
// particle on top of its bound (contactPushWithin): two sides moving 0.4 (d - m) + 0.1 (d - m/2)
// each keep 0.9 m between them, and no pair closes below m/2
#define SIM_CONTACT_PUSH_FRACTION 0.1f
// The part of the excess a pair's half-space takes out of a particle's step (slideExcess) that it
// passes on to the other primitive (contactPassed): the pull or push the sheet had against a layer
// moves the layer instead of vanishing. A half passes the motion of pressed layers to and fro so
// that a crumple on a floor never comes to rest; a tenth lets it rest and frees a strip held under
// a fold of the sheet it hangs from (Contact.AStripHeldUnderAFoldIsPulledFree)
#define SIM_CONTACT_PASS_FRACTION 0.1f
// How far a pair's normal (slideConstraint) may turn from rounding, per unit of the largest
// coordinate of its particles (and one) over their distance: far above the rounding of the nearest
// points and their difference (a few parts in 2^23 of the coordinates)
#define SIM_CONTACT_SLACK 1.52587890625e-5f
// The thickness of the contact, per unit of contact radius: closer pairs are pushed apart
#define SIM_CONTACT_THICKNESS 0.5f
// Fixed-point units of the contact pushes per unit of thickness (contactFixed), and the largest
// magnitude of one pair's push on one particle in those units: 2^11 such pushes sum within an int
#define SIM_CONTACT_FIXED 262144.0f
#define SIM_CONTACT_FIXED_MAX 1048576.0f
// SimUniforms::contact_check.mode: every triangle is checked for crossing the sheet in the first substep
#define SIM_CONTACT_CHECK_ALL 1u
// Ticks between two checks of every triangle for crossing the sheet (and the first tick with contact on)
#define SIM_CONTACT_AUDIT_TICKS 60u
// The pair lists' skin, per unit of contact radius: they hold every pair closer than the radius
// and the skin, and stand until a particle has travelled SIM_CONTACT_TRAVEL skins from where it was
// when they were built (a little under half: two particles closing in cannot lose a pair)
#define SIM_CONTACT_SKIN 0.25f
#define SIM_CONTACT_TRAVEL 0.45f
// The GPU's pair lists: words of their header, and the pairs a query keeps (one with more searches
// the grid every substep)
#define SIM_CONTACT_LIST_HEADER 5u
#define SIM_CONTACT_LIST_CAPACITY 16u
// The settle stage's half-spaces (settle_bodies.h), listed by particle: room for this many a
// particle on average (a particle whose list ends past them is not moved), on the CPU and the GPU
#define SIM_CONTACT_HALF_CAPACITY 16u
// The settle stage's sweeps at most (the contact_settle key)
#define SIM_SETTLE_MAX_SWEEPS 64u
// The GPU's contact grid: words of its header in SIM_BIND_CONTACT_GRID (x the bits of the longest
// live edge's squared length, y 1 when a triangle crosses another, z the particles in contact, w 1
// when the pair lists are built this substep, then 1 when the grid is built this substep and 1 when a
// list overflowed in this substep's build; from word 8 what contact_clear gathers: contactFrame's
// lo and hi as orderedBits and the bits of `lowest`, the box of the particles' travel since the
// lists were built as orderedBits, and the frame that contact_bound works out from what was
// gathered; from word 24 the settle's: 1 when an edge is over the limit as it starts, then per
// sweep 1 when the sweep worked on an edge), and
// the cells a box spans at most (cells as wide as the longest edge and the contact diameter, with
// room to spare for rounding: two a side)
#define SIM_CONTACT_HEADER (25u + SIM_SETTLE_MAX_SWEEPS)
// The header's word that says the grid is built in this substep (a fleet's gates read it)
#define SIM_CONTACT_WORD_GRID 4u
#define SIM_CONTACT_CELLS_PER_BOX 8u
#define SIM_CONTACT_CELL_ROOM 1.01f

// Largest workgroup count in X of one dispatch; bigger grids spill into Y
#define SIM_MAX_GROUPS_X 65535u

#endif
