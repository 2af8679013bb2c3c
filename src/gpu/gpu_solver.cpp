#include "gpu_solver.h"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>

#include "gpu/barriers.h"
#include "gpu/shaders.h"
#include "gpu/sim_pipeline.h"

namespace tender::gpu {

using namespace shaderio;

static_assert(sizeof(ScanPush) == 16);
static_assert(sizeof(PickPush) == 48);

GpuSolver::GpuSolver(std::unique_ptr<VulkanContext> ctx, FusedShape fused)
    : owned_ctx_(std::move(ctx)), ctx_(*owned_ctx_) {
  createPipelines(fused);
}

GpuSolver::GpuSolver(VulkanContext& ctx, FusedShape fused) : ctx_(ctx) { createPipelines(fused); }

GpuSolver::~GpuSolver() {
  VkDevice dev = ctx_.device();
  vkDeviceWaitIdle(dev);
  destroySheet();
  for (InFlight& s : in_flight_) {
    if (s.fence) vkDestroyFence(dev, s.fence, nullptr);
    if (s.queries) vkDestroyQueryPool(dev, s.queries, nullptr);
  }
  if (normals_fence_) vkDestroyFence(dev, normals_fence_, nullptr);
  if (normals_queries_) vkDestroyQueryPool(dev, normals_queries_, nullptr);
  ctx_.destroyBuffer(small_readback_);
  if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
}

void GpuSolver::createPipelines(FusedShape fused) {
  VkDevice dev = ctx_.device();
  // One set layout: the uniforms (dynamic offset per tick in flight) and every storage array.
  set_layout_ = createSheetSetLayout(dev);
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, uint32_t(sizeof(PickPush))};
  VkPipelineLayoutCreateInfo pli{};
  pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &set_layout_;
  pli.pushConstantRangeCount = 1;
  pli.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(dev, &pli, nullptr, &layout_));

  // The rules of float arithmetic (NoContraction everywhere, the device's float controls) and the
  // switches of exact_math.h: the environment may ask for an emulated inexact device
  // (TENDER_EMULATE_INEXACT_MATH=1) and, to show what the correction does, for none
  // (TENDER_UNCORRECTED_MATH=1).
  float_rules_ = simFloatRules(ctx_);
  math_ = MathSwitches::fromEnvironment();
  // The fused tick keeps the positions in shared memory; its shape suits the device.
  const FusedShape shape = resolveFusedShape(ctx_, fused);
  fused_workgroup_ = shape.workgroup;
  fused_substeps_ = shape.substeps_per_dispatch;
  fused_max_cell_spacings_ = shape.max_cell_spacings;
  fused_contact_ = shape.contact > 0;
  // What every sheet runs, whatever its path: the reset, the normals and the picks. A path's own
  // pipelines, contact's included, wait for its first tick (makePathPipelines).
  std::vector<PipelineRequest> requests;
  for (const PipelineRequest& r : passPipelineRequests(ctx_, pipes_, false))
    if (r.out == &pipes_.reset || r.out == &pipes_.normals) requests.push_back(r);
  for (uint32_t s = 0; s < 3; ++s) requests.push_back({&pipes_.pick[s], "pick.comp", sizeof(PickPush), 1, s, false});
  makeComputePipelines(ctx_, {layout_, "solver"}, float_rules_, math_, requests);

  // Per tick in flight: fences and timestamp pools (chain of timestamps at pass boundaries).
  VkFenceCreateInfo fci{};
  fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  for (InFlight& s : in_flight_) VK_CHECK(vkCreateFence(dev, &fci, nullptr, &s.fence));
  makeQueryPools();
  VkQueryPoolCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  VK_CHECK(vkCreateFence(dev, &fci, nullptr, &normals_fence_));
  if (ctx_.timestampsSupported()) {
    qci.queryCount = 2;
    VK_CHECK(vkCreateQueryPool(dev, &qci, nullptr, &normals_queries_));
  }
  small_readback_ = ctx_.createHostBuffer(256, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
}

void GpuSolver::makeQueryPools() {
  // The timestamps of a tick: the chain at the categories' boundaries, and with timeKernels one
  // after every dispatch (a tick of the per-colour passes records a few hundred a substep)
  query_capacity_ = 2 + marksPerSubstep() * SIM_MAX_SUBSTEPS + (time_kernels_ ? kKernelTimestamps : 0u);
  VkDevice dev = ctx_.device();
  VkQueryPoolCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qci.queryCount = query_capacity_;
  for (InFlight& s : in_flight_) {
    if (s.queries) vkDestroyQueryPool(dev, s.queries, nullptr);
    s.queries = VK_NULL_HANDLE;
    if (ctx_.timestampsSupported()) VK_CHECK(vkCreateQueryPool(dev, &qci, nullptr, &s.queries));
  }
}

uint32_t GpuSolver::kernelOf(VkPipeline p) const {
  uint32_t k = 0;
#define SIM_KERNEL_OF(name, push, per_invocation, batched)                                                             \
  if (pipes_.name.pipeline == p) return k;                                                                             \
  ++k;
  SIM_KERNELS(SIM_KERNEL_OF)
#undef SIM_KERNEL_OF
  return SIM_NONE;
}

void GpuSolver::timeKernels(bool on) {
  if (on == time_kernels_) return;
  time_kernels_ = on;
  last_kernel_ms_.clear();
  for (InFlight& s : in_flight_) waitFor(s);
  makeQueryPools();
  for (InFlight& s : in_flight_) s.recorded.reset(); // recorded again, with or without the timestamps
}

void GpuSolver::writeStaticUniforms() {
  // What the normals and pick passes read outside a tick.
  SimUniforms u{};
  u.particle_count = topo_.particleCount();
  u.cols = topo_.cols;
  u.rows = topo_.rows;
  u.constraint_count = topo_.constraintCount();
  u.triangle_count = topo_.triangleCount();
  u.hash_mask = topo_.hash_size - 1;
  u.color_count = topo_.colorCount();
  u.grab_index = SIM_NONE;
  std::memcpy(static_cast<char*>(buf_[SIM_BIND_UNIFORMS].mapped) + kStaticUniforms * uniform_stride_, &u, sizeof(u));
}

void GpuSolver::waitFor(InFlight& flight) const {
  if (!flight.pending) return;
  VK_CHECK(vkWaitForFences(ctx_.device(), 1, &flight.fence, VK_TRUE, UINT64_MAX));
  if (flight.timed) collectTimes(flight);
  flight.pending = flight.timed = false;
}

void GpuSolver::collectTimes(const InFlight& flight) const {
  if (!flight.queries || flight.categories.empty()) return;
  std::vector<uint64_t> ts(flight.categories.size() + 1);
  VK_CHECK(vkGetQueryPoolResults(ctx_.device(), flight.queries, 0, uint32_t(ts.size()), ts.size() * sizeof(uint64_t),
                                 ts.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  std::array<double, kCategoryCount> ms{};
  last_kernel_ms_.assign(time_kernels_ ? std::size(kKernelNames) : 0u, {0.0, 0u});
  double dispatches = 0.0; // the dispatches timed apart since the last category's mark, which it takes
  for (size_t k = 0; k < flight.categories.size(); ++k) {
    const double t = double(ts[k + 1] - ts[k]) * ctx_.timestampPeriod() * 1e-6;
    const uint32_t c = flight.categories[k];
    if (c < kCategoryCount) {
      ms[c] += dispatches + t;
      dispatches = 0.0;
    } else if (c - kCategoryCount < last_kernel_ms_.size()) { // a dispatch timed apart (timeKernels)
      last_kernel_ms_[c - kCategoryCount].first += t;
      ++last_kernel_ms_[c - kCategoryCount].second;
      dispatches += t;
    }
  }
  ms[kNormals] = last_ms_[kNormals];
  last_ms_ = ms;
}

void GpuSolver::tick(const SimUniforms& u) {
  const bool contact = u.contact.radius > 0.0f;
  // The contact's buffers, the first time contact is on (its pipelines: makePathPipelines)
  if (contact && !layout_sizes_.contact) sizeContact();
  last_contact_ = contact;
  const uint32_t index = next_in_flight_;
  next_in_flight_ = (next_in_flight_ + 1) % kInFlight;
  InFlight& flight = in_flight_[index];
  // Its previous tick has finished: its uniforms and command buffer may be reused.
  waitFor(flight);
  SimUniforms gpu_u = u;
  if (usesCandidateLists()) gpu_u.flags |= SIM_FLAG_CANDIDATES;
  if (contact) {
    gpu_u.contact_grid = {layout_sizes_.contact_buckets / 2 - 1, layout_sizes_.contact_counts,
                          layout_sizes_.contact_fill, layout_sizes_.contact_edges};
    gpu_u.contact_check.half_offset = layout_sizes_.contact_half;
    gpu_u.contact_check.list_capacity = contact_list_capacity_;
  }
  std::memcpy(static_cast<char*>(buf_[SIM_BIND_UNIFORMS].mapped) + index * uniform_stride_, &gpu_u, sizeof(gpu_u));
  if (u.reset_active) {
    ctx_.submit(flight.reset, flight.fence);
    flight.pending = true;
    dispatches_per_tick_ = 1;
    fused_tick_ = false;
    return;
  }
  const RecordKey key{substepCount(u.substeps), usesFusedPath(u), substepPlan(u, stop_after_)};
  stop_after_ = SIM_NONE;
  if (flight.recorded != key) {
    makePathPipelines(key.fused, runsWhen(SIM_WHEN_CONTACT, key.plan.when));
    recordTick(flight, index, key);
  }
  ctx_.submit(flight.tick, flight.fence);
  flight.pending = true;
  flight.timed = true;
  last_tick_ = int(index);
  dispatches_per_tick_ = flight.dispatches;
  fused_tick_ = key.fused;
}

void GpuSolver::makePathPipelines(bool fused, bool contact) {
  // The fused tick (with contact or without), or every per-colour pass not made yet (contact's
  // with contact): lavapipe translates and optimises a shader at each vkCreateComputePipelines (its
  // cache keeps only the compiled code), 1.2 s for a small sheet's 48 pipelines, and a sheet that
  // stays on one path never runs the other's
  std::vector<PipelineRequest> requests;
  if (fused && !contact && !pipes_.tick_fused.pipeline)
    requests.push_back({&pipes_.tick_fused, "tick_fused.comp", sizeof(FusedPush), 1, fused_workgroup_, true});
  if (fused && contact && !pipes_.tick_fused_contact.pipeline)
    requests.push_back(
        {&pipes_.tick_fused_contact, "tick_fused_contact.comp", sizeof(FusedPush), 1, fused_workgroup_, true});
  if (!fused)
    for (const PipelineRequest& r : passPipelineRequests(ctx_, pipes_, false, contact))
      if (!r.out->pipeline) requests.push_back(r);
  if (!requests.empty()) makeComputePipelines(ctx_, {layout_, "solver"}, float_rules_, math_, requests);
}

uint32_t GpuSolver::barrierPhasesPerTick() {
  if (!fused_tick_) return 0;
  finish();
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    const VkBufferCopy region{offsetof(shaderio::Counters, phases), 0, sizeof(uint32_t)};
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_COUNTERS].buffer, small_readback_.buffer, 1, &region);
  });
  uint32_t phases = 0;
  std::memcpy(&phases, small_readback_.mapped, sizeof(phases));
  return phases;
}

void GpuSolver::finish() {
  for (InFlight& s : in_flight_) waitFor(s);
  if (normals_pending_) {
    VK_CHECK(vkWaitForFences(ctx_.device(), 1, &normals_fence_, VK_TRUE, UINT64_MAX));
    normals_pending_ = false;
    if (normals_queries_) {
      uint64_t ts[2];
      VK_CHECK(vkGetQueryPoolResults(ctx_.device(), normals_queries_, 0, 2, sizeof(ts), ts, sizeof(uint64_t),
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
      last_ms_[kNormals] = double(ts[1] - ts[0]) * ctx_.timestampPeriod() * 1e-6;
    }
  }
}

void GpuSolver::computeNormals() {
  if (normals_pending_) finish();
  ctx_.submit(normals_cmd_, normals_fence_);
  normals_pending_ = true;
}

PickResult GpuSolver::pick(glm::vec3 o, glm::vec3 d, float radius) {
  finish();
  PickPush push{};
  push.origin_radius = vec4(o, radius);
  push.dir = vec4(d, 0.0f);
  push.count = topo_.particleCount();
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    PickResult init{};
    init.index = SIM_NONE;
    init.d2 = 0x7F800000u; // +inf
    vkCmdUpdateBuffer(cmd, buf_[SIM_BIND_PICK].buffer, 0, sizeof(init), &init);
    transferToCompute(cmd);
    bindSet(cmd, kStaticUniforms);
    for (int s = 0; s < 3; ++s) {
      dispatch(cmd, pipes_.pick[size_t(s)], Grid::Threads, push.count, push);
      computeToAll(cmd);
    }
    VkBufferCopy region{0, 0, sizeof(PickResult)};
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_PICK].buffer, small_readback_.buffer, 1, &region);
  });
  bound_ = VK_NULL_HANDLE;
  PickResult r;
  std::memcpy(&r, small_readback_.mapped, sizeof(r));
  return r;
}

glm::vec3 GpuSolver::particlePosition(uint32_t index) { return particlePositions({index})[0]; }

std::vector<glm::vec3> GpuSolver::particlePositions(const std::vector<uint32_t>& indices) {
  finish();
  std::vector<glm::vec3> out(indices.size());
  if (indices.empty()) return out;
  // Into the small read-back buffer when they fit, a buffer of their own otherwise.
  Buffer own;
  const VkDeviceSize bytes = 16ull * indices.size();
  if (bytes > small_readback_.size) own = ctx_.createHostBuffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  const Buffer& dst = own.buffer ? own : small_readback_;
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    std::vector<VkBufferCopy> regions;
    for (size_t k = 0; k < indices.size(); ++k) regions.push_back({16ull * indices[k], 16ull * k, 16});
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_POS].buffer, dst.buffer, uint32_t(regions.size()), regions.data());
  });
  for (size_t k = 0; k < indices.size(); ++k) {
    glm::vec4 p;
    std::memcpy(&p, static_cast<const char*>(dst.mapped) + 16 * k, sizeof(p));
    out[k] = glm::vec3(p);
  }
  ctx_.destroyBuffer(own);
  return out;
}

PassTimes GpuSolver::passTimes() const {
  // Collect the newest finished tick without waiting for one still running.
  if (last_tick_ >= 0) {
    InFlight& s = in_flight_[size_t(last_tick_)];
    if (s.pending && vkGetFenceStatus(ctx_.device(), s.fence) == VK_SUCCESS) waitFor(s);
  }
  if (normals_pending_ && vkGetFenceStatus(ctx_.device(), normals_fence_) == VK_SUCCESS && normals_queries_) {
    uint64_t ts[2];
    VK_CHECK(vkGetQueryPoolResults(ctx_.device(), normals_queries_, 0, 2, sizeof(ts), ts, sizeof(uint64_t),
                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    last_ms_[kNormals] = double(ts[1] - ts[0]) * ctx_.timestampPeriod() * 1e-6;
    normals_pending_ = false;
  }
  static const char* kNames[kCategoryCount] = {"contact", "integrate", "project", "hash",      "collide",
                                               "floor",   "tear",      "normals", "fused_tick"};
  PassTimes t;
  for (int c = 0; c < kCategoryCount; ++c) t.ms.emplace_back(kNames[c], last_ms_[size_t(c)]);
  for (size_t k = 0; k < last_kernel_ms_.size(); ++k)
    if (last_kernel_ms_[k].second > 0) t.kernels.emplace_back(kKernelNames[k], last_kernel_ms_[k].first);
  return t;
}

Arithmetic GpuSolver::arithmetic() const { return arithmeticOf(float_rules_, math_); }

FusedShape resolveFusedShape(const VulkanContext& ctx, FusedShape requested, bool fleet) {
  const bool cpu_device = ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  FusedShape shape;
  const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
  const uint32_t most =
      std::min({uint32_t(SIM_WG_FUSED_MAX), limits.maxComputeWorkGroupInvocations, limits.maxComputeWorkGroupSize[0]});
  shape.workgroup = std::min<uint32_t>(requested.workgroup ? requested.workgroup
                                       : cpu_device        ? SIM_WG_FUSED_CPU
                                       : fleet             ? SIM_WG_FUSED_FLEET
                                                           : SIM_WG_FUSED,
                                       most);
  shape.substeps_per_dispatch = requested.substeps_per_dispatch ? requested.substeps_per_dispatch
                                : cpu_device                    ? SIM_FUSED_SUBSTEPS_CPU
                                                                : SIM_MAX_SUBSTEPS;
  shape.max_cell_spacings = requested.max_cell_spacings != 0.0f ? requested.max_cell_spacings
                            : cpu_device                        ? SIM_FUSED_CPU_MAX_CELL_SPACINGS
                                                                : -1.0f;
  // Contact's loops have no bound within lavapipe's loop count: a CPU device runs contact sheets on
  // the per-colour passes, alone and in a fleet
  shape.contact = requested.contact ? requested.contact : cpu_device ? -1 : 1;
  return shape;
}

float structuralSpacing(const SheetTopology& topo) {
  float spacing = std::numeric_limits<float>::max();
  for (const Constraint& k : topo.constraints)
    if ((k.kind_id & SIM_KIND_MASK) == SIM_KIND_STRUCTURAL) spacing = std::min(spacing, k.rest);
  return spacing;
}

bool fusedTickFits(const SheetTopology& topo, uint32_t capacity) {
  return topo.particleCount() <= capacity && topo.hash_size <= 2u * std::bit_ceil(capacity);
}

bool fusedTickTakes(const SimUniforms& u, float spacing, float max_cell_spacings, bool contact_in_workgroup) {
  if (u.contact.radius > 0.0f && !contact_in_workgroup) return false;
  if ((u.flags & SIM_FLAG_COLLISION) == 0u || max_cell_spacings < 0.0f) return true;
  return u.inv_cell * max_cell_spacings * spacing >= 1.0f;
}

bool GpuSolver::usesFusedPath() const { return fused_allowed_ && fusedTickFits(topo_, fusedCapacity(ctx_)); }

bool GpuSolver::usesFusedPath(const SimUniforms& u) const {
  return usesFusedPath() && fusedTickTakes(u, spacing_, fused_max_cell_spacings_, fused_contact_);
}

} // namespace tender::gpu
