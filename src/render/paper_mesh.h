#pragma once
/// Host-visible copies of the paper's arrays, for solvers whose state lives on the CPU: the
/// renderer draws them exactly as it draws the GPU solver's buffers.
#include "core/solver.h"
#include "renderer.h"

namespace tender::gpu {
class GpuSolver;
}

namespace tender::render {

/// The GPU solver's own buffers as the renderer binds them (no copy).
PaperBuffers gpuPaperBuffers(gpu::GpuSolver& solver);

/// One set of host-visible buffers (pos, normal, uv, triangles, draw arguments).
class HostPaperMesh {
public:
  /// Buffers for a sheet of this topology; uv is written once.
  HostPaperMesh(gpu::VulkanContext& ctx, const SheetTopology& topo);
  ~HostPaperMesh();
  HostPaperMesh(const HostPaperMesh&) = delete;
  HostPaperMesh& operator=(const HostPaperMesh&) = delete;

  /// Copies positions, normals and the live triangles of a read-back state.
  void update(const SimState& state);
  /// The buffers, for Renderer::setPaper.
  PaperBuffers buffers() const;

private:
  gpu::VulkanContext& ctx_;
  gpu::Buffer pos_, normal_, uv_, triangles_, args_;
  uint32_t particles_ = 0, triangle_capacity_ = 0;
};

} // namespace tender::render
