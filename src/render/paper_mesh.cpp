#include "paper_mesh.h"

#include "gpu/gpu_solver.h"

#include <algorithm>
#include <cstring>

namespace tender::render {

PaperBuffers gpuPaperBuffers(gpu::GpuSolver& solver) {
  return {solver.positionBuffer(), solver.normalBuffer(),  solver.uvBuffer(),
          solver.triangleBuffer(), solver.counterBuffer(), gpu::GpuSolver::kDrawArgsOffset};
}

HostPaperMesh::HostPaperMesh(gpu::VulkanContext& ctx, const SheetTopology& topo) : ctx_(ctx) {
  particles_ = std::max(topo.particleCount(), 1u);
  triangle_capacity_ = std::max(topo.triangleCount(), 1u);
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  pos_ = ctx.createHostBuffer(sizeof(glm::vec4) * particles_, storage);
  normal_ = ctx.createHostBuffer(sizeof(glm::vec4) * particles_, storage);
  uv_ = ctx.createHostBuffer(sizeof(glm::vec2) * particles_, storage);
  triangles_ = ctx.createHostBuffer(sizeof(glm::uvec4) * triangle_capacity_, storage);
  args_ = ctx.createHostBuffer(sizeof(VkDrawIndirectCommand), VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  std::memset(pos_.mapped, 0, pos_.size);
  std::memset(normal_.mapped, 0, normal_.size);
  std::memset(uv_.mapped, 0, uv_.size);
  std::memset(triangles_.mapped, 0, triangles_.size);
  std::memcpy(uv_.mapped, topo.uv.data(), sizeof(glm::vec2) * topo.uv.size());
  VkDrawIndirectCommand none{0, 1, 0, 0};
  std::memcpy(args_.mapped, &none, sizeof(none));
}

HostPaperMesh::~HostPaperMesh() {
  for (gpu::Buffer* b : {&pos_, &normal_, &uv_, &triangles_, &args_}) ctx_.destroyBuffer(*b);
}

void HostPaperMesh::update(const SimState& s) {
  size_t n = std::min<size_t>(s.pos.size(), particles_);
  std::memcpy(pos_.mapped, s.pos.data(), sizeof(glm::vec4) * n);
  std::memcpy(normal_.mapped, s.normal.data(), sizeof(glm::vec4) * std::min(n, s.normal.size()));
  uint32_t tris = std::min<uint32_t>({s.triangle_count, triangle_capacity_, uint32_t(s.triangles.size())});
  std::memcpy(triangles_.mapped, s.triangles.data(), sizeof(glm::uvec4) * tris);
  VkDrawIndirectCommand args{3 * tris, 1, 0, 0};
  std::memcpy(args_.mapped, &args, sizeof(args));
}

PaperBuffers HostPaperMesh::buffers() const {
  return {pos_.buffer, normal_.buffer, uv_.buffer, triangles_.buffer, args_.buffer, 0};
}

} // namespace tender::render
