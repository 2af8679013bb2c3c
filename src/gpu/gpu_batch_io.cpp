// GpuBatch's transfers: a sheet's uploads, resets and read-backs of its slices (through the
// transfers GpuSolver uses too, sheet_transfers.cpp), and every sheet's positions in one read-back
// (gpu_batch.h); gpu_batch.cpp creates the batch and runs its ticks.
#include <cstring>
#include <stdexcept>

#include "core/host_queries.h"
#include "gpu/barriers.h"
#include "gpu_batch.h"

namespace tender::gpu {

using namespace shaderio;

SheetPlace GpuBatch::place(uint32_t i) const {
  SheetPlace where;
  for (uint32_t b = 0; b < kSheetBindingCount; ++b) {
    where.buffer[b] = buf_[b].buffer;
    where.offset[b] = sliceOffset(b, i);
    where.size[b] = stride_[b];
  }
  return where;
}

void GpuBatch::uploadSheet(uint32_t i, const SheetTopology& topo) {
  finish();
  if (allocated_ && topo.contact && !sizes_.contact) {
    // The first sheet made with contact on: the fleet sizes its contact buffers, which it can do
    // while no sheet has ticked, and uploads the sheets made before again
    if (ticked_)
      throw std::runtime_error("contact_factor was turned on in a fleet made without it: a fleet on the GPU "
                               "needs it set when its sheets are made");
    SheetTopology with = topo_;
    with.contact = true;
    releaseSlices();
    allocate(with);
    for (uint32_t j = 0; j < uploaded_.size(); ++j)
      if (uploaded_[j] && j != i) {
        StartData start;
        uploadStart(ctx_, place(j), sheetBindings(topo_, sizes_, start, true));
      }
  }
  if (!allocated_) allocate(topo);
  if (uploaded_.size() < size()) uploaded_.resize(size(), false);
  uploaded_[i] = true;
  // Every sheet shares the topology: the restored bindings of a reset come from topo_.
  if (topo.cols != topo_.cols || topo.rows != topo_.rows || topo.constraints.size() != topo_.constraints.size() ||
      topo.triangles.size() != topo_.triangles.size() || topo.colors.size() != topo_.colors.size() ||
      std::memcmp(topo.constraints.data(), topo_.constraints.data(), topo.constraints.size() * sizeof(Constraint)) != 0)
    throw std::invalid_argument("the sheets of a fleet share their topology (grid, spacing and constraint families)");
  StartData start;
  const std::vector<BindingSpec> table = sheetBindings(topo, sizes_, start, true);
  uploadStart(ctx_, place(i), table);
}

void GpuBatch::resetSheet(uint32_t i) {
  finish();
  beginSheetReset(ctx_, place(i), topo_, sizes_);
}

void GpuBatch::readSheet(uint32_t i, SimState& out) {
  finish();
  readSheetState(ctx_, place(i), topo_, sizes_, out);
  gridNormals(out.pos, topo_.cols, topo_.rows, out.normal);
}

glm::vec4 GpuBatch::readParticle(uint32_t i, uint32_t particle) {
  finish();
  glm::vec4 p;
  ctx_.download(buf_[SIM_BIND_POS], &p, sizeof(p), sliceOffset(SIM_BIND_POS, i) + 16ull * particle);
  return p;
}

int64_t GpuBatch::sheetContacts(uint32_t i) {
  if (!contact_on_[i] || !sizes_.contact) return -1;
  finish();
  return readContactCount(ctx_, buf_[SIM_BIND_CONTACT_GRID], sliceOffset(SIM_BIND_CONTACT_GRID, i));
}

std::vector<glm::vec4> GpuBatch::readSheetPositions(uint32_t i) {
  finish();
  std::vector<glm::vec4> pos(topo_.particleCount());
  ctx_.download(buf_[SIM_BIND_POS], pos.data(), 16ull * pos.size(), sliceOffset(SIM_BIND_POS, i));
  return pos;
}

void GpuBatch::readSheetDeltas(uint32_t i, std::vector<glm::vec4>& out) {
  finish();
  out.resize(topo_.particleCount());
  ctx_.download(buf_[SIM_BIND_DELTA], out.data(), 16ull * out.size(), sliceOffset(SIM_BIND_DELTA, i));
}

void GpuBatch::readPositions(std::vector<glm::vec4>& pos, std::vector<glm::vec4>& prev) {
  flush();
  finish();
  const uint32_t n = topo_.particleCount();
  const VkDeviceSize bytes = 16ull * n * size();
  pos.resize(size_t(n) * size());
  prev.resize(pos.size());
  if (!allocated_ || bytes == 0) return;
  // Both arrays of every sheet into one host buffer, in one submission.
  Buffer staging = ctx_.createHostBuffer(2 * bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    std::vector<VkBufferCopy> pos_regions, prev_regions;
    for (uint32_t i = 0; i < size(); ++i) {
      pos_regions.push_back({sliceOffset(SIM_BIND_POS, i), 16ull * n * i, 16ull * n});
      prev_regions.push_back({sliceOffset(SIM_BIND_PREV, i), bytes + 16ull * n * i, 16ull * n});
    }
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_POS].buffer, staging.buffer, uint32_t(pos_regions.size()), pos_regions.data());
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_PREV].buffer, staging.buffer, uint32_t(prev_regions.size()),
                    prev_regions.data());
  });
  std::memcpy(pos.data(), staging.mapped, size_t(bytes));
  std::memcpy(prev.data(), static_cast<const char*>(staging.mapped) + bytes, size_t(bytes));
  ctx_.destroyBuffer(staging);
}

} // namespace tender::gpu
