// tender-bench's memory-traffic model and peak-bandwidth measurements (see traffic.h).
#include "traffic.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "core/solver.h"
#include "cpu/worker_pool.h"

#ifdef TENDER_HAS_GPU
#include "gpu/barriers.h"
#include "gpu/context.h"
#endif

namespace tender::bench {

namespace {

// Record sizes, from the types the solvers store.
using Topo = SheetTopology;
constexpr uint64_t kPos = sizeof(decltype(SimState::pos)::value_type);    // pos, prev, delta; GPU cell_pos
constexpr uint64_t kRest = sizeof(decltype(Topo::rest_pos)::value_type);  // rest_pos
constexpr uint64_t kUv = sizeof(decltype(Topo::uv)::value_type);          // uv (integrate reads u)
constexpr uint64_t kIndex = sizeof(decltype(Topo::adj_list)::value_type); // every index, count and bucket array
constexpr uint64_t kConstraint = sizeof(shaderio::Constraint);            // GPU constraints, CPU constraints_
// CpuSolver projects from the constraints split into con_a_, con_b_, con_kind_ (indices) and con_rest_.
constexpr uint64_t kSplitConstraint = 3 * kIndex + sizeof(float);
// CpuSolver's integer cell per particle (particle_coord_, sorted_coord_: ivec4) and its
// hash-ordered positions (sorted_x_, sorted_y_, sorted_z_: one float each).
constexpr uint64_t kCoord = sizeof(glm::ivec4);
constexpr uint64_t kSortedPos = 3 * sizeof(float);

/// The hash and collide passes' traffic with the candidate lists in use.
void listTraffic(uint64_t n, bool cpu, bool fused, PassTraffic& hash, PassTraffic& collide) {
  // The candidate lists in use (a substep that rebuilds them runs the hash and the search
  // below): each particle reads the position its list was built at and its current one (the
  // travel test; fused: the current one in shared memory), then its list's count and its
  // position (fused: shared memory), and writes delta. The entries and their positions depend
  // on how close the sheet comes to itself and are not counted.
  const uint64_t base = cpu ? kSortedPos : kPos; // CpuCollision's candidate bases hold xyz only
  hash.read += n * (base + (fused ? 0 : kPos));
  collide.read += n * (kIndex + (fused ? 0 : kPos));
  collide.write += n * kPos;
}

/// The CPU's spatial hash and collision, without lists.
void hashTrafficCpu(uint64_t n, uint64_t buckets, uint64_t adjacency, PassTraffic& hash, PassTraffic& collide) {
  // hash (CpuCollision::buildHash), step by step:
  hash.read += n * kPos;                     // cell of each particle: read pos,
  hash.write += n * (kCoord + kIndex);       //   write particle_coord_, particle_cell_
  hash.read += n * 2 * kIndex;               // count: read particle_cell_ and a count per particle,
  hash.write += n * kIndex;                  //   write the count back
  hash.read += buckets * kIndex;             // exclusive scan: read cell_count_,
  hash.write += (2 * buckets + 1) * kIndex;  //   write cell_start_ (shifted by one) and clear cell_count_
  hash.read += n * 2 * kIndex;               // scatter: read particle_cell_ and its cursor in cell_start_,
  hash.write += n * 3 * kIndex;              //   write the cursor, particle_slot_ and cell_particles_
  hash.read += n * (kIndex + kPos + kCoord); // gather in bucket order: read cell_particles_, pos, particle_coord_,
  hash.write += n * (kSortedPos + kCoord);   //   write sorted_x_/y_/z_, sorted_coord_
  // collide: read every particle's hash-ordered position and cell and its slot
  // (cell_particles_), the bucket starts (27 lookups per particle spread over the whole table)
  // and its adjacency (offsets and list); write delta (in hash order).
  collide.read += n * (kSortedPos + kCoord + kIndex) + (buckets + 1) * kIndex + (n + 1) * kIndex + adjacency * kIndex;
  collide.write += n * kPos;
}

/// The GPU's spatial hash and collision, without lists.
void hashTrafficGpu(uint64_t n, uint64_t buckets, PassTraffic& hash, PassTraffic& collide) {
  // hash, the GPU passes (scan_add runs when the scan has more than one block).
  const uint64_t scans = buckets > SIM_SCAN_BLOCK ? 2 : 1;
  hash.read += n * (kPos + kIndex);       // hash_count: read pos and (atomic) the bucket's count,
  hash.write += n * 2 * kIndex;           //   write particle_cell and the count
  hash.read += scans * buckets * kIndex;  // scan (+ scan_add): read cell_count (cell_start),
  hash.write += scans * buckets * kIndex; //   write cell_start; the block sums are negligible
  hash.read += n * 3 * kIndex;            // hash_scatter: read particle_cell, bucket start, (atomic) count,
  hash.write += n * 2 * kIndex;           //   write the count and cell_scatter
  hash.read += n * (3 * kIndex + kPos);   // hash_sort: read particle_cell, the bucket start, the bucket's
                                          //   cell_scatter entries (each once overall) and pos,
  hash.write += n * (kIndex + kPos);      //   write cell_particles and cell_pos (position and index)
  // collide: read pos, the bucket starts (27 lookups per particle spread over the whole table),
  // every bucket entry (cell_pos: position and index in one record) and the particle's
  // adjacency mask over its grid stencil (the adjacency list only for rare far neighbours); write delta.
  collide.read += n * kPos + (buckets + 1) * kIndex + n * kPos + n * kIndex;
  collide.write += n * kPos;
}

} // namespace

std::vector<PassTraffic> tickTraffic(const SheetTopology& topo, const shaderio::SimUniforms& u, Layout layout,
                                     bool candidate_lists) {
  const bool cpu = layout == Layout::Cpu, fused = layout == Layout::GpuFused;
  const bool collision = (u.flags & SIM_FLAG_COLLISION) != 0u, tear = shaderio::tearingOn(u.tear_factor);
  const uint64_t n = topo.particleCount();         // particles
  const uint64_t slots = topo.constraintCount();   // constraint slots (the GPU's tear pass covers all)
  const uint64_t buckets = topo.hash_size;         // T: cell_count[T], cell_start[T + 1]
  const uint64_t adjacency = topo.adj_list.size(); // CSR neighbour entries
  const uint64_t substeps = shaderio::substepCount(u.substeps);
  uint64_t live = 0; // live constraints, summed over the colours
  for (const ColorRange& c : topo.colors) live += c.count;
  const uint64_t constraint = cpu ? kSplitConstraint : kConstraint;

  PassTraffic integrate{"integrate"}, project{"project"}, hash{"hash"}, collide{"collide"}, floor{"floor"},
      tear_pass{"tear"};

  // integrate: read pos, prev, rest_pos, uv; write pos, prev. (Fused: counted in project below,
  // where its time is.)
  PassTraffic& verlet = fused ? project : integrate;
  verlet.read += n * (2 * kPos + kRest + kUv);
  verlet.write += n * 2 * kPos;

  // project, per iteration and colour: read each constraint record and both end positions, write
  // both positions (no two constraints of a colour share a particle, so each position once per
  // colour). Fused: positions stay in shared memory; only the constraints come from memory. The
  // colour ranges and uniforms (a few bytes per dispatch) are not counted.
  for (uint32_t it = 0; it < u.iterations; ++it)
    for (const ColorRange& c : topo.colors) {
      project.read += c.count * (fused ? constraint : constraint + 2 * kPos);
      project.write += fused ? 0 : c.count * 2 * kPos;
    }

  if (collision && candidate_lists)
    listTraffic(n, cpu, fused, hash, collide);
  else if (collision && cpu)
    hashTrafficCpu(n, buckets, adjacency, hash, collide);
  else if (collision)
    hashTrafficGpu(n, buckets, hash, collide);

  // floor: read pos, prev and (with collision) delta (on the CPU through particle_slot_); write pos, prev.
  floor.read += n * (collision ? 3 : 2) * kPos + (collision && cpu && !candidate_lists ? n * kIndex : 0);
  floor.write += n * 2 * kPos;

  // tear marking: read the constraint records and every position (each particle ends several
  // constraints; counted once). The GPU pass runs over every slot and reads the torn flag of
  // each; the fused tick and the CPU read the live ranges only. Nothing is written unless
  // something tears; the compaction then runs, which this steady-state model leaves out.
  if (tear) {
    tear_pass.read += cpu ? live * kSplitConstraint : fused ? live * kConstraint : slots * (kConstraint + kIndex);
    tear_pass.read += fused ? 0 : n * kPos;
  }

  std::vector<PassTraffic> passes = {integrate, project, hash, collide, floor, tear_pass};
  for (PassTraffic& p : passes) {
    p.read *= substeps;
    p.write *= substeps;
  }
  return passes;
}

namespace {

using Clock = std::chrono::steady_clock;

// Large enough to leave the caches of the machines this runs on, small enough to stay quick.
constexpr uint64_t kHostCopyBytes = 256ull << 20;
constexpr uint64_t kDeviceCopyBytes = 256ull << 20;
constexpr uint32_t kCopyRepetitions = 5;

} // namespace

PeakBandwidth measureHostCopy(uint32_t threads) {
  WorkerPool pool(threads);
  const uint32_t workers = pool.size();
  const uint64_t bytes = kHostCopyBytes;
  struct Free {
    void operator()(void* p) const { std::free(p); }
  };
  std::unique_ptr<char, Free> src(static_cast<char*>(std::aligned_alloc(4096, bytes)));
  std::unique_ptr<char, Free> dst(static_cast<char*>(std::aligned_alloc(4096, bytes)));
  // Each worker copies its own contiguous share (and first touches it, in the warm-up).
  const uint64_t share = (bytes / workers) & ~uint64_t(4095);
  auto copy = [&](uint32_t w) {
    const uint64_t begin = w * share, end = w + 1 == workers ? bytes : begin + share;
    std::memcpy(dst.get() + begin, src.get() + begin, end - begin);
  };
  pool.run(workers, [&](uint32_t w) {
    const uint64_t begin = w * share, end = w + 1 == workers ? bytes : begin + share;
    std::memset(src.get() + begin, 1, end - begin);
  });
  pool.run(workers, copy); // warm-up: the destination's pages
  double best = 0.0;
  for (uint32_t r = 0; r < kCopyRepetitions; ++r) {
    const auto t0 = Clock::now();
    pool.run(workers, copy);
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (s > 0.0) best = std::max(best, 2.0 * double(bytes) / s / 1e9);
  }
  return {best, bytes, kCopyRepetitions, workers, "memcpy on " + std::to_string(workers) + " thread(s)"};
}

#ifdef TENDER_HAS_GPU
std::optional<PeakBandwidth> measureDeviceCopy(int device, std::string& error) {
  using namespace gpu;
  gpu::ContextOptions options;
  options.device = device;
  auto created = VulkanContext::create(options);
  if (!created) {
    error = created.error();
    return std::nullopt;
  }
  VulkanContext& ctx = **created;
  if (!ctx.timestampsSupported()) {
    error = "the queue has no timestamps";
    return std::nullopt;
  }
  // At most an eighth of the device-local memory per buffer.
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(ctx.physicalDevice(), &mem);
  VkDeviceSize heap = 0;
  for (uint32_t h = 0; h < mem.memoryHeapCount; ++h)
    if (mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) heap = std::max(heap, mem.memoryHeaps[h].size);
  const VkDeviceSize bytes = std::min<VkDeviceSize>(kDeviceCopyBytes, std::max<VkDeviceSize>(heap / 8, 1ull << 20));
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

  VkQueryPoolCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qci.queryCount = 2 * kCopyRepetitions;
  VkQueryPool queries = VK_NULL_HANDLE;
  VK_CHECK(vkCreateQueryPool(ctx.device(), &qci, nullptr, &queries));
  Buffer src = ctx.createDeviceBuffer(bytes, usage), dst = ctx.createDeviceBuffer(bytes, usage);
  ctx.submitOnce([&](VkCommandBuffer cmd) {
    vkCmdResetQueryPool(cmd, queries, 0, qci.queryCount);
    // Fill both (the pages exist before timing), then copy: one untimed, then timed ones.
    vkCmdFillBuffer(cmd, src.buffer, 0, VK_WHOLE_SIZE, 0x3f800000u);
    vkCmdFillBuffer(cmd, dst.buffer, 0, VK_WHOLE_SIZE, 0u);
    const VkBufferCopy region{0, 0, bytes};
    auto transferToTransfer = [&] {
      memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                    VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
    };
    for (uint32_t r = 0; r <= kCopyRepetitions; ++r) {
      transferToTransfer();
      if (r > 0) vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 2 * (r - 1));
      vkCmdCopyBuffer(cmd, src.buffer, dst.buffer, 1, &region);
      if (r > 0) vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 2 * (r - 1) + 1);
    }
  });
  std::vector<uint64_t> ts(qci.queryCount);
  VK_CHECK(vkGetQueryPoolResults(ctx.device(), queries, 0, qci.queryCount, ts.size() * sizeof(uint64_t), ts.data(),
                                 sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  double best = 0.0;
  for (uint32_t r = 0; r < kCopyRepetitions; ++r) {
    const double s = double(ts[2 * r + 1] - ts[2 * r]) * ctx.timestampPeriod() * 1e-9;
    if (s > 0.0) best = std::max(best, 2.0 * double(bytes) / s / 1e9);
  }
  ctx.destroyBuffer(src);
  ctx.destroyBuffer(dst);
  vkDestroyQueryPool(ctx.device(), queries, nullptr);
  return PeakBandwidth{best, bytes, kCopyRepetitions, 0,
                       std::string("vkCmdCopyBuffer on ") + ctx.properties().deviceName};
}
#endif

} // namespace tender::bench
