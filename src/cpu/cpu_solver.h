#pragma once
/// The CPU reference solver: every pass of one tick over flat arrays, in float32, in the same
/// order as the GPU solver, calling the same per-element maths (shaders/shared/xpbd.h).
#include <vector>

#include "core/solver.h"

namespace tender {

class CpuSolver final : public Solver {
public:
  std::string name() const override { return "cpu"; }
  void upload(const SheetTopology& topo) override;
  void tick(const shaderio::SimUniforms& u) override;
  void beginReset() override;
  void computeNormals() override;
  shaderio::PickResult pick(glm::vec3 o, glm::vec3 d, float radius) override;
  glm::vec3 particlePosition(uint32_t index) override { return glm::vec3(pos_[index]); }
  void readback(SimState& out) override;
  uint32_t dispatchesPerTick() const override { return passes_per_tick_; }

  // The passes of one substep, public so tests can drive them one by one.
  /// Verlet integration with gravity, wind, damping; pins and the grab hold their particles.
  void integrate(const shaderio::SimUniforms& u, uint32_t substep);
  /// Gauss-Seidel over the colours, `iterations` times.
  void project(const shaderio::SimUniforms& u, uint32_t iterations);
  /// Rebuilds the spatial hash: count, scan, scatter (particles of a cell in index order).
  void buildHash(const shaderio::SimUniforms& u);
  /// Gathers repulsion from non-adjacent neighbours into the delta array (Jacobi).
  void collide(const shaderio::SimUniforms& u);
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

private:
  const SheetTopology* topo_ = nullptr;
  std::vector<glm::vec4> pos_, prev_, rest_, normal_, delta_, reset_from_;
  std::vector<glm::vec2> uv_;
  std::vector<shaderio::Constraint> constraints_;
  std::vector<ColorRange> colors_;
  std::vector<uint32_t> torn_;
  std::vector<glm::uvec4> triangles_;
  uint32_t triangle_count_ = 0;
  std::vector<uint32_t> cell_count_, cell_start_, cell_particles_, particle_cell_;
  uint32_t passes_per_tick_ = 0;
};

} // namespace tender
