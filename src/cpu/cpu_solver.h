#pragma once
/// The CPU reference solver: every pass of one tick over flat arrays, in float32, in the same
/// order as the GPU solver, calling the same per-element maths (shaders/shared/xpbd.h).
/// Parallel loops (the constraints of one colour, per-particle passes, the collision gather) are
/// split over a small thread pool; every element is computed exactly as in one thread, so the
/// results are bitwise identical whatever the thread count.
#include <memory>
#include <vector>

#include "core/solver.h"

namespace tender {

class WorkerPool;

/// How the CPU solver spreads its work over threads.
struct CpuOptions {
  uint32_t threads = 1;   ///< worker threads, the caller included; 0 = one per hardware thread
  uint32_t min_chunk = 0; ///< smallest loop share worth a thread; 0 = tuned defaults, 1 = split every loop (tests)
  /// Keep collision candidate lists (SIM_NEAR_* in sim_config.h, as the GPU solver): a substep
  /// whose particles have not travelled too far since the lists were built sums its repulsion
  /// from them instead of building the hash. The results are the same either way.
  bool collision_lists = true;
};

class CpuSolver final : public Solver {
public:
  /// A solver running on `options.threads` threads (one by default: the plain reference).
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
  uint32_t dispatchesPerTick() const override { return passes_per_tick_; }
  /// Bytes of host memory of the solver's own arrays (capacity, not size).
  uint64_t memoryBytes() const override;
  /// Worker threads in use, the caller included.
  uint32_t threadCount() const;
  /// True when the solver keeps collision candidate lists (CpuOptions::collision_lists).
  bool usesCollisionLists() const { return options_.collision_lists; }

  // The passes of one substep, public so tests can drive them one by one.
  /// Verlet integration with gravity, wind, damping; pins and the grab hold their particles.
  void integrate(const shaderio::SimUniforms& u, uint32_t substep);
  /// Gauss-Seidel over the colours, `iterations` times.
  void project(const shaderio::SimUniforms& u, uint32_t iterations);
  /// Rebuilds the spatial hash: count, scan, scatter (particles of a cell in index order), then
  /// gathers positions and cells in that order for the collision pass.
  void buildHash(const shaderio::SimUniforms& u);
  /// Gathers repulsion from non-adjacent neighbours into the delta array (Jacobi); needs buildHash.
  void collide(const shaderio::SimUniforms& u);
  /// The collision of one substep: from the candidate lists when they hold every pair that can
  /// touch, else buildHash and the gather, which rebuilds the lists unless they were outgrown too
  /// fast of late. Returns the mode (SIM_NEAR_*).
  uint32_t collideSubstep(const shaderio::SimUniforms& u);
  /// Applies the collision deltas, then the ground contact.
  void floorPass(const shaderio::SimUniforms& u);
  /// Marks constraints beyond the tear threshold; returns how many tore.
  uint32_t markTears(const shaderio::SimUniforms& u);
  /// Stable compaction of the colour ranges and of the triangles that lost an edge.
  void compact();
  /// One frame of the animated reset.
  void resetPass(const shaderio::SimUniforms& u);

  /// Direct access for tests.
  std::vector<glm::vec4>& positions() { return pos_; }
  std::vector<glm::vec4>& previous() { return prev_; }
  const std::vector<uint32_t>& cellStart() const { return cell_start_; }
  const std::vector<uint32_t>& cellParticles() const { return cell_particles_; }
  /// The candidate lists' state (as the GPU's Counters::near).
  glm::uvec4 listState() const { return near_state_; }

private:
  void projectRange(const float stiffness[4], uint32_t begin, uint32_t end);
  /// Gather for hash slots [begin, end) within `search` (>= the radius); with `build`, also the
  /// candidate lists of those particles; true when every list fits.
  bool collideRange(const shaderio::SimUniforms& u, uint32_t begin, uint32_t end, float search, bool build);
  glm::vec3 listRepulsion(const shaderio::SimUniforms& u, uint32_t i) const;
  uint32_t markTearsRange(const shaderio::SimUniforms& u, uint32_t begin, uint32_t end);
  void splitConstraints();
  /// Smallest loop share worth a thread: options_.min_chunk when set; no sharing at all on a sheet
  /// too small to pay for the hand-offs (kSmallSheet in cpu_solver.cpp); else the tuned value.
  uint32_t grain(uint32_t tuned) const { return options_.min_chunk ? options_.min_chunk : small_sheet_ ? ~0u : tuned; }

  CpuOptions options_;
  std::unique_ptr<WorkerPool> pool_;
  const SheetTopology* topo_ = nullptr;
  std::vector<glm::vec4> pos_, prev_, rest_, normal_, reset_from_;
  std::vector<glm::vec4> delta_; // collision delta of each hash slot (hash order: no false sharing)
  std::vector<glm::vec2> uv_;
  std::vector<shaderio::Constraint> constraints_;
  std::vector<ColorRange> colors_;
  // constraints_ split into arrays for SIMD loads, each colour ordered by first particle
  std::vector<uint32_t> con_a_, con_b_, con_kind_, con_id_;
  std::vector<float> con_rest_;
  bool avx_ = false; // the 8-wide kernels run on this CPU
  std::vector<uint32_t> torn_;
  std::vector<glm::uvec4> triangles_;
  uint32_t triangle_count_ = 0;
  std::vector<uint32_t> adj_offsets_, adj_list_; // CSR adjacency (copied from the topology)
  std::vector<uint32_t> cell_count_, cell_start_, cell_particles_, particle_cell_;
  std::vector<uint32_t> particle_slot_;               // hash slot of each particle (cell_particles_ inverted)
  std::vector<glm::ivec4> particle_coord_;            // integer cell of each particle
  std::vector<float> sorted_x_, sorted_y_, sorted_z_; // positions in hash order (SoA, padded)
  std::vector<glm::ivec4> sorted_coord_;              // cells in hash order
  bool delta_by_particle_ = false;                    // delta_ indexed by particle (lists), not hash slot
  std::vector<uint32_t> near_list_;                   // candidate lists, SIM_NEAR_STRIDE words per particle
  std::vector<glm::vec3> near_base_;                  // positions the lists were built at
  glm::uvec4 near_state_{0u};                         // x usable, y age, z wait, w search bits
  uint32_t passes_per_tick_ = 0;
  bool small_sheet_ = false; // every loop on the calling thread (see grain)
};

} // namespace tender
