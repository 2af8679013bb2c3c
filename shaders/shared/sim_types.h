// GPU-visible structs shared by GLSL and C++ (4-byte scalars and vec4/uvec4 only).
// In C++ this file is included inside `namespace shaderio { using namespace glm; }`.
#ifndef SIM_TYPES_H
#define SIM_TYPES_H
#include "prelude.h"
#include "sim_config.h"

/// A distance constraint between particles a and b.
/// kind_id = (original id << SIM_KIND_BITS) | kind; the original id indexes `torn`.
struct Constraint {
  uint a;
  uint b;
  float rest;
  uint kind_id;
};

// The keys of SimUniforms, one struct a topic: 16 bytes each, at offsets that are multiples of 16,
// so std140, std430 and C++ lay them out alike (shaderio.h checks). A fleet's kernels read one
// whole where they read two of its fields (SpirvRules).

/// The air on each triangle (SIM_FLAG_AIR, airOnTriangle in xpbd.h).
struct AirKeys {
  float pressure;      // SimParams::airPressureFactor's pressure
  float friction;      // its friction factor
  float third_over_dt; // 1 / (3 dt)
  float unused;
};

/// The sheet's hinges (SIM_KIND_HINGE): constraints first .. first + count - 1.
struct HingeRange {
  uint first; // original id of the first hinge (hinge k is constraint first + k)
  uint count; // hinges
  uint unused0;
  uint unused1;
};

/// The hinges' bending and creases (solveHinge, creaseReturn in xpbd.h).
struct CreaseKeys {
  float compliance;  // the XPBD compliance of an edge hinge over dt^2 (a diagonal's is half)
  float yield_angle; // radians (0: elastic, no creases)
  float hardening;
  float unused;
};

/// The hand closing around the grab (handPull in xpbd.h), zero while it is open.
struct HandKeys {
  float fist;  // the fist's radius
  float reach; // how far around the grab it draws the sheet in (0: open)
  float draw;  // the part of a particle's way into the fist it is drawn per substep
  float grip;  // the part of its velocity relative to the hand the grip takes per substep
};

/// The hand's motion.
struct HandMotion {
  vec3 per_substep; // its displacement per substep
  float lowest;     // the lowest the fist's centre goes (floor + HandKeys::fist)
};

/// Penetration-free contact (contact.h).
struct ContactKeys {
  float radius;      // the contact radius (0: off)
  float fraction;    // the part of its distance to the nearest primitive a particle may move in a substep (below 1/2)
  float thickness;   // closer pairs are pushed apart
  float fixed_units; // the fixed-point units of a push per unit of length (contactFixed)
};

/// Contact's checks and the GPU's places for its scratch.
struct ContactChecks {
  uint mode;          // which triangles are checked for crossing the sheet (SIM_CONTACT_CHECK_*: crossingChecked)
  uint sweeps;        // the settle stage's sweeps (contact_settle; 0 without the stretch limit)
  uint half_offset;   // the GPU's scratch offset of the settle's half-space counts, then starts (particles + 1),
                      // their fills (particles) and their scan's sums (the solver fills it in)
  uint list_capacity; // the GPU's pairs a contact query keeps in its list (at most SIM_CONTACT_LIST_CAPACITY)
};

/// The GPU's contact grid (the solver fills it in): the triangles' buckets are the first mask + 1,
/// the edges' the next mask + 1.
struct ContactGrid {
  uint mask;   // the hash mask of each half
  uint counts; // the scratch offset of its bucket counts (then starts)
  uint fills;  // the scratch offset of its bucket fills
  uint edges;  // the sheet's edges (SIM_BIND_CONTACT_LISTS)
};

/// The stretch limit (limitParticle in sim_bodies.h).
struct LimitKeys {
  float reach;     // the longest a structural edge may be after the projection (stretch_limit x spacing; 0: off)
  float rest;      // its rest length (the spacing)
  float last_ring; // the last ring from limitRootSet's roots (limitLastRing, a whole number)
  float unused;
};

/// The Verlet step of the first substep.
struct VerletKeys {
  // the damping of the first substep, which also rescales the velocity its previous position carries
  // from the last tick's substeps to this tick's (damping x dt / the last tick's dt, when the substeps
  // key changed between them or the hand's pace asks for more, Simulation::tickParams)
  float first_damping;
  // that rescale alone (dt / the last tick's dt; 0 when they are the same), which the contact's
  // frame takes too (contactFrameScale)
  float rescale;
  float unused0;
  float unused1;
};

/// Per-tick inputs of the simulation (one uniform buffer, std140 == C++ layout).
struct SimUniforms {
  uint particle_count; // N
  uint cols;           // grid width
  uint rows;           // grid height
  uint substeps;       // substeps per tick (<= SIM_MAX_SUBSTEPS)

  uint constraint_count; // original constraint count (size of `torn`)
  uint triangle_count;   // original triangle count
  uint hash_mask;        // hash table size - 1 (table size is a power of two >= 2N)
  uint color_count;      // number of colours

  float dt;      // substep length in seconds
  float damping; // Verlet velocity factor per substep
  float gravity; // magnitude, pointing -Y
  float floor_y; // ground height

  float restitution;      // normal velocity kept on floor contact
  float friction;         // tangential velocity removed on floor contact
  float collision_radius; // repulsion distance (collision_factor x spacing)
  float inv_cell;         // 1 / hash cell size

  float collision_stiffness; // fraction of the overlap corrected per substep
  float tear_factor;         // tear beyond tear_factor x rest; 0 disables tearing
  uint tear_kinds;           // bit k set: constraints of kind k may tear
  uint flags;                // SIM_FLAG_*

  vec4 stiffness; // projection stiffness per kind (structural, shear, bend, tri-bend)

  uint grab_index;   // grabbed particle or SIM_NONE
  uint reset_active; // 1 while the animated reset runs (physics passes are skipped)
  float reset_alpha; // reset interpolation factor of this frame, 0..1
  uint iterations;   // constraint iterations per substep

  AirKeys air; // SIM_FLAG_AIR

  HingeRange hinge;
  CreaseKeys crease;
  HandKeys hand;
  HandMotion hand_motion;
  ContactKeys contact;
  ContactChecks contact_check;
  ContactGrid contact_grid;

  LimitKeys limit;
  // The roots its rings run from (limitRootSet in xpbd.h): xyz the particles (SIM_NONE past the
  // last), w how many (0: the grabbed particle, else the sheet's middle)
  uvec4 limit_roots;
  VerletKeys verlet;

  vec4 wind[SIM_MAX_SUBSTEPS];        // uniform wind acceleration at each substep
  vec4 wind_twist[SIM_MAX_SUBSTEPS];  // wind acceleration scaled by (u - 0.5) across the sheet
  vec4 grab_target[SIM_MAX_SUBSTEPS]; // grabbed particle position per substep; w: 0 free, 1 held, 2 tossed
  vec4 grab_prev[SIM_MAX_SUBSTEPS];   // its previous position (equal to target: zero velocity)
};

// SimUniforms.flags bits
#define SIM_FLAG_COLLISION 1u
#define SIM_FLAG_PINS 2u
// Set by the GPU solver when it keeps collision candidate lists (SIM_CANDIDATE_* in sim_config.h)
#define SIM_FLAG_CANDIDATES 4u
// Air on every triangle (airOnTriangle in xpbd.h): a pass before integration sums it per particle
#define SIM_FLAG_AIR 8u

/// The state of one hinge (SIM_BIND_HINGES, SheetState::hinges): x its rest angle (radians, in
/// (-pi, pi]; 0 on a flat sheet, moved by creasing), y the yield its hardening has added, z and w
/// unused (0).
#define HingeState vec4

/// Push constants of every simulation dispatch.
struct SimPush {
  uint first;   // first element (particle, ...); the projection: the iteration
  uint count;   // element count of this dispatch
  uint substep; // substep index inside the tick
  uint color;   // colour index for projection and compaction
};

/// Push constants of the fused small-sheet tick: substeps [first_substep, first_substep + substeps)
/// of the tick in one workgroup.
struct FusedPush {
  uint count;         // particles
  uint first_substep; // first substep of this dispatch
  uint substeps;      // substeps of this dispatch
  uint stop;          // last pass of the tick to run (passesPerSubstep numbering), SIM_NONE: all
};

/// What every dispatch of a fleet adds to its pass's push constants: the device address of the
/// fleet's table (SIM_BATCH_* in sim_config.h), where its sheets start in the table's queue, and
/// (the per-colour passes, tick_batch's aside) which of those sheets the pass runs for.
struct BatchArgs {
  uvec2 table;  // address (low, high 32 bits) of SIM_BATCH_ENTRIES uvec4: xy sheet 0's address, zw the stride
  uint first;   // the dispatch's sheet k (workgroup k of the fused tick, workgroup z = k of a pass) is queue[first + k]
  uint substep; // the pass's substep
  uint when;    // the conditions its sheets meet (SIM_WHEN_* bits, stageConditions)
  uint live;    // SIM_LIVE_*: its gate at run time
  uint arg;     // SIM_LIVE_ITERATION: the iteration; SIM_LIVE_SWEEP: the sweep
  uint pad0;
};

/// Push constants of the batched fused tick of a fleet (tick_batch.comp).
struct BatchPush {
  FusedPush fused;
  BatchArgs batch;
};

/// Push constants of a batched per-colour pass (shaders/sim/*.comp built with SIM_BATCH_PASS): the
/// pass's own (SimPush or ScanPush, both 16 bytes; zeros for a pass without), then the batch's.
struct BatchPassPush {
  SimPush pass;
  BatchArgs batch;
};

/// GPU counters: tear bookkeeping and indirect arguments (one storage buffer).
struct Counters {
  uint torn_total;        // constraints torn since the last reset
  uint torn_new;          // constraints marked in the current substep
  uint triangle_count;    // live triangles
  uint phases;            // the fused tick's workgroup barriers in its last tick (sync, fused_tick.glsl)
  uvec4 compact_dispatch; // indirect dispatch for compaction (x = 0 when nothing tore)
  uvec4 draw_args;        // indirect draw: vertexCount, instanceCount, firstVertex, firstInstance
  // Collision candidate lists: x 1 when usable, y substeps since they were built, z substeps to
  // wait before building them again, w the bits of the radius + skin they hold
  uvec4 candidate_state;
  // This substep: x a particle travelled too far for the lists, y a list overflowed
  uvec4 candidate_flags;
};

/// Result of a pick: the nearest particle to a ray and where it is (SIM_BIND_PICK, read back).
struct PickResult {
  uint index; // particle or SIM_NONE
  float t;    // ray parameter of the point nearest to the particle
  uint d2;    // float bits of its squared distance to the ray (the passes' running minimum)
  uint pad;
  vec4 pos; // its position (w: inverse mass)
};

/// Push constants of the scan passes (block scan and block-sum add).
struct ScanPush {
  uint mode;   // SIM_SCAN_HASH: cell_count -> cell_start; SIM_SCAN_SCRATCH: in place in scratch
  uint offset; // first element in scratch (SIM_SCAN_SCRATCH)
  uint count;  // elements to scan
  uint sums;   // scratch offset of the per-block sums
};
#define SIM_SCAN_HASH 0u
#define SIM_SCAN_SCRATCH 1u

/// Push constants of the pick passes: a ray and a radius.
struct PickPush {
  vec4 origin_radius; // xyz ray origin, w pick radius
  vec4 dir;           // xyz unit direction
  uint count;         // particle count
  uint pad0;
  uint pad1;
  uint pad2;
};

/// A particle's contact in a substep (SIM_BIND_CONTACT): xyz where it starts the substep and w its
/// step bound (contact_bound); xyz the push that parts its close pairs (contactAverage); x the
/// bits of its squared distance to the nearest primitive, y 1 when it is free (its triangle crosses
/// another) and 2 when it was in the last substep, z its share of its step after the floor
/// (slideShare); its pushes (after the floor: its steps' excess) in fixed point (two's complement)
/// and their count; what its pairs pass on to it after the floor (contactPassed) likewise.
struct ContactParticle {
  vec4 start;
  vec4 push;
  uvec4 state;
  uvec4 sum;
  uvec4 passed;
};

#endif
