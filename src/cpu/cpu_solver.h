#pragma once
/// The CPU reference solver: every pass of one tick over flat arrays, in float32, in the order of
/// the pass table (SIM_STAGES, shaders/shared/sim_passes.h) as the GPU solver. It runs the
/// shaders' own per-element bodies where they are written in the shared dialect (the projection,
/// the air and the tear marks: sim_bodies.h, through SheetElements) and the same per-element maths
/// elsewhere (xpbd.h, collision.h): the collision gather and the tear compaction are its own loops
/// (a serial stable compaction where the GPU scans), with the same bits. Parallel loops (the
/// constraints of one colour, per-particle passes, the collision gather) are split over a small
/// thread pool; every element is computed exactly as in one thread, so the results are bitwise
/// identical whatever the thread count. The projection, the tear test and the collision gather
/// also have SIMD kernels (simd_kernels.h) with the very bits of the scalar bodies;
/// CpuOptions::simd = false runs the scalar reference alone.
#include <memory>
#include <optional>
#include <vector>

#include "core/passes.h"
#include "core/solver.h"
#include "cpu_collision.h"
#include "cpu_contact.h"
#include "sheet_elements.h"

namespace tender {

class WorkerPool;

/// How the CPU solver spreads its work over threads, and which of its equivalent paths it takes.
struct CpuOptions {
  uint32_t threads = 1;   ///< worker threads, the caller included; 0 = one per hardware thread
  uint32_t min_chunk = 0; ///< smallest loop share worth a thread; 0 = tuned defaults, 1 = split every loop (tests)
  /// Keep collision candidate lists (SIM_CANDIDATE_* in sim_config.h, as the GPU solver): a substep
  /// whose particles have not travelled too far since the lists were built sums its repulsion
  /// from them instead of building the hash. The results are the same either way.
  bool candidate_lists = true;
  /// Run the SIMD kernels (simd_kernels.h: SSE, and AVX where the CPU has it) for the projection,
  /// the tear test and the collision gather; off runs the scalar reference alone. The results are
  /// bitwise the same either way.
  bool simd = true;
};

class CpuSolver final : public Solver {
public:
  /// A solver running on `options.threads` threads (one by default).
  explicit CpuSolver(CpuOptions options = {});
  ~CpuSolver() override;

  std::string name() const override { return "cpu"; }
  void upload(const SheetTopology& topo) override;
  void tick(const shaderio::SimUniforms& u) override;
  void beginReset() override;
  void computeNormals() override;
  shaderio::PickResult pick(glm::vec3 o, glm::vec3 d, float radius) override;
  glm::vec3 particlePosition(uint32_t index) override { return glm::vec3(pos_[index]); }
  void readback(SimState& out) override;
  void stopNextTickAfter(uint32_t last_pass) override { stop_after_ = last_pass; }
  /// The test hook of `tender diff`: a one-ULP change planted after one pass of one tick.
  void setPlantedUlp(std::optional<PlantedUlp> plant) { plant_ = plant; }
  void readDeltas(std::vector<glm::vec4>& out) override;
  Arithmetic arithmetic() const override;
  uint32_t dispatchesPerTick() const override { return passes_per_tick_; }
  int64_t contacts() const override { return contact_on_ ? int64_t(contact_.contacts()) : -1; }
  /// The times contact's pair lists were built whole, and repaired, so far.
  uint32_t contactListBuilds() const { return contact_.listBuilds(); }
  uint32_t contactListRepairs() const { return contact_.listRepairs(); }
  /// Bytes of host memory of the solver's own arrays (capacity, not size).
  uint64_t memoryBytes() const override;
  /// Worker threads in use, the caller included.
  uint32_t threadCount() const;
  /// True when the solver keeps collision candidate lists (CpuOptions::candidate_lists).
  bool usesCandidateLists() const { return options_.candidate_lists; }
  /// True when the SIMD kernels run (CpuOptions::simd, in a build that has them).
  bool usesSimd() const { return simd_; }

  // The passes of one substep, public so tests can drive them one by one.
  /// Passes [first, first + count) of stage `stage` (SIM_STAGES) of substep `substep`: what a
  /// tick runs for that stage (count > 1 only for a stage numbered once per colour).
  void runStage(PassKind stage, const shaderio::SimUniforms& u, uint32_t when, uint32_t substep, uint32_t first,
                uint32_t count);
  /// Verlet integration with gravity, wind, damping (and with `air` the air on each particle,
  /// from airPass); pins and the grab hold their particles.
  void integrate(const shaderio::SimUniforms& u, uint32_t substep, bool air);
  /// The air on each particle (airOnParticle in sim_elements.glsl), from the positions and previous
  /// positions of the start of the substep.
  void airPass(const shaderio::SimUniforms& u);
  /// Gauss-Seidel over the colours, `iterations` times.
  void project(const shaderio::SimUniforms& u, uint32_t iterations) {
    projectColors(u, 0, iterations * uint32_t(colors_.size()));
  }
  /// Colour passes [first, first + count) of the Gauss-Seidel sweep (pass k: colour k % colours of
  /// iteration k / colours).
  void projectColors(const shaderio::SimUniforms& u, uint32_t first, uint32_t count);
  /// Colour passes [first, first + count) of the shorten stage (shortenConstraint over each
  /// colour with edges, as projectColors numbers them), while limitShortens.
  void shortenColors(const shaderio::SimUniforms& u, uint32_t first, uint32_t count);
  /// The creases of the substep (creaseHinge), when the sheet creases.
  void creasePass(const shaderio::SimUniforms& u);
  /// The stretch limit: the rings around its root one after the other (limitParticle).
  void limitPass(const shaderio::SimUniforms& u);
  /// The collision of one substep (CpuCollision::substep); returns the mode (SIM_CANDIDATE_*).
  uint32_t collide(const shaderio::SimUniforms& u) { return collision_.substep(u, pos_.data()); }
  /// Moves the free particles by the collision deltas (repelParticle), before the projection.
  void repelPass(const shaderio::SimUniforms& u);
  /// The ground contact; with contact on (SimUniforms::contact),
  /// no free particle ends farther from where it started the substep than its bound (contact.h).
  void floorPass(const shaderio::SimUniforms& u, uint32_t substep, bool contact);
  /// The settle stage, with contact and its sweeps on (SimUniforms::contact_check.sweeps): the
  /// half-spaces listed by particle, then the sweeps over the structural edges of each colour.
  void settlePass(const shaderio::SimUniforms& u, uint32_t s);
  /// How many structural edges each colour holds at its head (the shorten and settle stages visit those).
  const std::vector<uint32_t>& countColourEdges();
  /// Marks constraints beyond the tear threshold; returns how many tore.
  uint32_t markTears(const shaderio::SimUniforms& u);
  /// After a tear: marks the shear and tri-bend constraints whose triangles are gone (unsupported
  /// in xpbd.h); returns how many.
  uint32_t markUnsupported(const shaderio::SimUniforms& u);
  /// Stable compaction of the colour ranges and of the triangles that lost an edge.
  void compact();
  /// One frame of the animated reset.
  void resetPass(const shaderio::SimUniforms& u);

  /// Positions (w = inverse mass), for tests.
  std::vector<glm::vec4>& positions() { return pos_; }
  /// Previous positions, for tests.
  std::vector<glm::vec4>& previous() { return prev_; }
  /// The hinges' states (HingeState), for tests.
  std::vector<glm::vec4>& hingeStates() { return hinges_; }
  /// The collision: spatial hash, gather, candidate lists.
  CpuCollision& collision() { return collision_; }
  /// First hash slot of each bucket, then the end (CpuCollision::cellStart).
  const std::vector<uint32_t>& cellStart() const { return collision_.cellStart(); }
  /// Particle in each hash slot (CpuCollision::cellParticles).
  const std::vector<uint32_t>& cellParticles() const { return collision_.cellParticles(); }
  /// The candidate lists' state (CpuCollision::candidateState).
  glm::uvec4 candidateState() const { return collision_.candidateState(); }

private:
  void projectRange(shaderio::SheetElements& e, const float stiffness[4], uint32_t iteration, uint32_t begin,
                    uint32_t end);
  void markTearsRange(shaderio::SheetElements& e, uint32_t begin, uint32_t end);
  /// The sheet as the shaders' element bodies read it (sim_bodies.h).
  shaderio::SheetElements elements(const shaderio::SimUniforms& u);
  void splitConstraints();

  CpuOptions options_;
  bool simd_ = false; // the SIMD kernels run (CpuOptions::simd, in a build that has them)
  std::unique_ptr<WorkerPool> pool_;
  Grain grain_;
  CpuCollision collision_;
  CpuContact contact_;
  bool contact_on_ = false;       ///< the last tick had contact on
  std::vector<glm::vec4> start_;  ///< with contact on: the positions at the start of the substep
  std::vector<float> bound_;      ///< with contact on: each particle's step bound in this substep
  std::vector<glm::vec4> passed_; ///< with contact on: what each step is passed by its pairs (contactPassed)
  std::vector<glm::vec4> excess_; ///< with contact on: each step's excess beyond its pairs' half-spaces
  std::vector<float> share_;      ///< with contact on: the share of each step that keeps them
  std::vector<glm::vec4> push_;   ///< with contact on: the push parting its contacts (CpuContact)
  const SheetTopology* topo_ = nullptr;
  std::vector<glm::vec4> pos_, prev_, rest_, normal_, reset_from_;
  std::vector<glm::vec4> air_; ///< the air on each particle in this substep (SIM_FLAG_AIR)
  std::vector<glm::vec2> uv_;
  std::vector<shaderio::Constraint> constraints_;
  std::vector<ColorRange> colors_;
  std::vector<uint32_t> project_passes_; ///< projectColors' passes that project (scratch)
  std::vector<uint32_t> settle_colours_; ///< settlePass's colours with edges (scratch)
  std::vector<uint32_t> colour_edges_;   ///< the structural edges at the head of each colour (countColourEdges)
  /// limitPass's rings from several roots: each particle's root, the particles in the rings'
  /// order from where ring 1 starts, for those roots
  std::vector<uint32_t> limit_root_of_, limit_order_;
  uint32_t limit_first_ = 0;
  glm::uvec4 limit_roots_{0u};
  // constraints_ split into one array per field, each colour ordered by first particle
  std::vector<uint32_t> con_a_, con_b_, con_kind_, con_id_;
  std::vector<uint32_t> con_hinge_; ///< per slot of a hinge: its hinge

  std::vector<uint32_t> hinge_corners_; ///< per hinge: its gridHinge (4 words)
  std::vector<float> con_rest_;
  std::vector<uint32_t> torn_;
  std::vector<glm::vec4> hinges_; ///< HingeState per hinge
  std::vector<glm::uvec4> triangles_;
  uint32_t triangle_count_ = 0;
  shaderio::Counters counters_{}; ///< the tear counts the element bodies keep (torn_new: this substep)
  uint32_t passes_per_tick_ = 0;
  uint32_t stop_after_ = SIM_NONE; // stopNextTickAfter
  uint64_t ticks_ = 0;             // ticks since upload (the clock of plant_)
  std::optional<PlantedUlp> plant_;
};

} // namespace tender
