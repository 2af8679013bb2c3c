#pragma once
/// The storage buffers of one sheet, described by one table of bindings: the size of each from
/// the topology, its start contents, whether a reset restores it and whether a read-back copies it.
/// The solver (one sheet) and the fleet (a slice of each buffer per sheet) both work from it.
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/sheet.h"
#include "core/solver.h"

namespace tender::gpu {

/// Sizes derived from the topology that the passes and the table share.
struct SheetLayout {
  uint32_t tear_slots = 0;               ///< constraints + triangles + 1: the compaction's scan length
  uint32_t tear_sums = 0, hash_sums = 0; ///< scratch offsets of the per-block sums
  bool candidates_fit = false;           ///< the candidate-list buffer fits a binding of the device
  /// Penetration-free contact: its buffers are sized (else one word each); the sheet's edges; the
  /// contact grid's buckets (two halves of a power of two: the triangles', the edges'); the scratch offsets of the
  /// buckets' counts (then starts, buckets + 1 of them), of their fills and of the counts' scan sums, of the
  /// queries' flags (then where each active one goes, queries + 1 of them) and their scan sums; the words of
  /// SIM_BIND_CONTACT_GRID, and of SIM_BIND_CONTACT_LISTS (the edges, then the lists)
  bool contact = false;
  uint32_t contact_edges = 0, contact_buckets = 0, contact_counts = 0, contact_fill = 0, contact_sums = 0;
  uint32_t contact_active = 0, contact_active_sums = 0;
  /// The settle stage's scratch: the particles' half-space counts (then starts, particles + 1),
  /// their fills (particles) and the counts' scan sums
  uint32_t contact_half = 0, contact_half_sums = 0;
  uint64_t contact_words = 0, contact_list_words = 0;
  /// The layout of a topology on a device that binds at most `max_range` bytes, with the contact's
  /// buffers sized or not.
  static SheetLayout of(const SheetTopology& topo, VkDeviceSize max_range, bool contact = false);
};

/// `v` rounded up to a multiple of `a`.
inline VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

/// True when ticks keep the collision candidate lists: they are allowed (GpuSolver and GpuBatch's
/// setCandidateLists) and their buffer fits the device. The one rule both engines follow.
inline bool keepsCandidateLists(const SheetLayout& layout, bool allowed) { return allowed && layout.candidates_fit; }

/// One storage buffer of the sheet.
struct BindingSpec {
  uint32_t binding = 0;
  VkDeviceSize bytes = 0;       ///< size, from the topology
  const void* data = nullptr;   ///< start contents (nullptr: zeros)
  VkDeviceSize data_bytes = 0;  ///< bytes of `data`
  VkDeviceSize data_offset = 0; ///< where in the buffer `data` goes
  bool restored = false;        ///< a reset restores it (what tearing changes)
  bool read_back = false;       ///< a read-back copies it
};

/// Start contents derived from the topology, which the table points into.
struct StartData {
  std::vector<glm::vec4> pos, normal;
  std::vector<uint32_t> adj_mask;
  std::vector<glm::uvec2> colors;
  std::vector<glm::uvec4> contact_edges;
  uint32_t last_start = 0;
  shaderio::Counters counters{};
};

/// Bindings of a sheet's descriptor set: the uniforms (SIM_BIND_UNIFORMS, a dynamic uniform buffer)
/// and every storage array, up to SIM_BIND_CONTACT_GRID.
constexpr uint32_t kSheetBindingCount = SIM_BIND_CONTACT_GRID + 1;

/// The layout of a sheet's descriptor set (kSheetBindingCount bindings).
VkDescriptorSetLayout createSheetSetLayout(VkDevice dev);

/// A pool of `sets` sheet descriptor sets.
VkDescriptorPool createSheetSetPool(VkDevice dev, uint32_t sets);

/// Points `set`'s bindings at `where[binding]` (the uniforms take sizeof(SimUniforms)).
void writeSheetSet(VkDevice dev, VkDescriptorSet set,
                   const std::array<VkDescriptorBufferInfo, kSheetBindingCount>& where);

/// The sheet's edges, each once, sorted by their particles (SIM_BIND_CONTACT_LISTS): xy its
/// particles a < b, zw the ids of the triangles that hold it (w SIM_NONE when only one does).
std::vector<glm::uvec4> contactEdges(const SheetTopology& topo);

/// Elements of the per-block sums of a scan of `count` elements (every level).
uint32_t scanSumsSize(uint32_t count);

/// The table of bindings of a topology (every storage binding, once). Without `particle_data`
/// the per-particle start contents (positions, normals, adjacency masks) are left out: what a
/// reset restores and what a read-back needs are cheap to point at.
std::vector<BindingSpec> sheetBindings(const SheetTopology& topo, const SheetLayout& layout, StartData& start,
                                       bool particle_data);

/// The state of a sheet from its read-back bindings: `bytes(binding)` points at the copy of each.
void assembleState(const SheetTopology& topo, const std::function<const void*(uint32_t binding)>& bytes, SimState& out);

class VulkanContext;
struct Buffer;

/// Where each binding of one sheet lives: a buffer, and the offset and size of the sheet's part of
/// it (a sheet alone: whole buffers; a fleet's sheet: its slices). The transfers below serve both.
struct SheetPlace {
  std::array<VkBuffer, kSheetBindingCount> buffer{};
  std::array<VkDeviceSize, kSheetBindingCount> offset{}, size{};
};

/// Records the start contents of a sheet's bindings into `place` (restored_only: only those a reset
/// restores): zeros, then the table's data from one staging buffer, created here (destroy it once
/// the submission has run).
void recordStart(VulkanContext& ctx, VkCommandBuffer cmd, const SheetPlace& place,
                 const std::vector<BindingSpec>& table, bool restored_only, Buffer& staging);

/// Uploads a sheet's start contents (every binding of `table`), in one submission.
void uploadStart(VulkanContext& ctx, const SheetPlace& place, const std::vector<BindingSpec>& table);

/// The start of an animated reset, in one submission: the sheet's positions go to where the reset
/// animates from (SIM_BIND_RESET_FROM), and what tearing changed is restored.
void beginSheetReset(VulkanContext& ctx, const SheetPlace& place, const SheetTopology& topo, const SheetLayout& sizes);

/// A sheet's state read back from `place`: every read-back binding into one staging buffer, in one
/// submission.
void readSheetState(VulkanContext& ctx, const SheetPlace& place, const SheetTopology& topo, const SheetLayout& sizes,
                    SimState& out);

/// The particles in contact in a sheet's last substep (Solver::contacts): the count contact_bound
/// keeps in its contact grid's header, `grid` from `offset` (a sheet alone: 0; a fleet's: its slice).
int64_t readContactCount(VulkanContext& ctx, const Buffer& grid, VkDeviceSize offset);

} // namespace tender::gpu
