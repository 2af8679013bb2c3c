// The table of a sheet's storage bindings: sizes, start contents, what a reset restores and
// what a read-back copies; and the state assembled from the read-back copies.
#include "gpu/sheet_buffers.h"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>

#include "gpu/context.h"

namespace tender::gpu {

using namespace shaderio;

namespace {

/// The adjacency of each particle as a mask over its 5 x 5 grid stencil (SIM_BIND_ADJ_MASK), so
/// that the collision gather tests a neighbour with a bit instead of a search.
std::vector<uint32_t> adjacencyMasks(const SheetTopology& topo) {
  constexpr int kReach = SIM_ADJ_STENCIL;
  std::vector<uint32_t> masks(topo.particleCount(), 0u);
  for (uint32_t i = 0; i < masks.size(); ++i)
    for (uint32_t k = topo.adj_offsets[i]; k < topo.adj_offsets[i + 1]; ++k) {
      const uint32_t j = topo.adj_list[k];
      const int dx = int(j % topo.cols) - int(i % topo.cols), dy = int(j / topo.cols) - int(i / topo.cols);
      if (std::abs(dx) <= kReach && std::abs(dy) <= kReach)
        masks[i] |= 1u << uint32_t((dy + kReach) * (2 * kReach + 1) + dx + kReach);
      else
        masks[i] |= SIM_ADJ_FAR;
    }
  return masks;
}

template <class T>
VkDeviceSize bytesOf(const std::vector<T>& v) {
  return VkDeviceSize(v.size()) * sizeof(T);
}

} // namespace

VkDescriptorSetLayout createSheetSetLayout(VkDevice dev) {
  std::array<VkDescriptorSetLayoutBinding, kSheetBindingCount> bindings{};
  for (uint32_t b = 0; b < kSheetBindingCount; ++b) {
    bindings[b].binding = b;
    bindings[b].descriptorType =
        b == SIM_BIND_UNIFORMS ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[b].descriptorCount = 1;
    bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo sli{};
  sli.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  sli.bindingCount = kSheetBindingCount;
  sli.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  VK_CHECK(vkCreateDescriptorSetLayout(dev, &sli, nullptr, &layout));
  return layout;
}

VkDescriptorPool createSheetSetPool(VkDevice dev, uint32_t sets) {
  VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, sets},
                                   {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, (kSheetBindingCount - 1) * sets}};
  VkDescriptorPoolCreateInfo dpi{};
  dpi.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dpi.maxSets = sets;
  dpi.poolSizeCount = 2;
  dpi.pPoolSizes = sizes;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VK_CHECK(vkCreateDescriptorPool(dev, &dpi, nullptr, &pool));
  return pool;
}

void writeSheetSet(VkDevice dev, VkDescriptorSet set,
                   const std::array<VkDescriptorBufferInfo, kSheetBindingCount>& where) {
  std::array<VkWriteDescriptorSet, kSheetBindingCount> writes{};
  for (uint32_t b = 0; b < kSheetBindingCount; ++b) {
    writes[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[b].dstSet = set;
    writes[b].dstBinding = b;
    writes[b].descriptorCount = 1;
    writes[b].descriptorType =
        b == SIM_BIND_UNIFORMS ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &where[b];
  }
  vkUpdateDescriptorSets(dev, kSheetBindingCount, writes.data(), 0, nullptr);
}

uint32_t scanSumsSize(uint32_t count) {
  uint32_t groups = (count + SIM_SCAN_BLOCK - 1) / SIM_SCAN_BLOCK;
  return groups + (groups > 1 ? scanSumsSize(groups) : 0);
}

std::vector<glm::uvec4> contactEdges(const SheetTopology& topo) {
  std::vector<glm::uvec4> e;
  e.reserve(3 * size_t(topo.triangleCount()));
  for (const glm::uvec4& t : topo.triangles)
    for (glm::uvec2 ab : {glm::uvec2(t.x, t.y), glm::uvec2(t.y, t.z), glm::uvec2(t.z, t.x)})
      e.emplace_back(std::min(ab.x, ab.y), std::max(ab.x, ab.y), t.w, SIM_NONE);
  std::sort(e.begin(), e.end(), [](glm::uvec4 a, glm::uvec4 b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  });
  // An edge of two triangles: one entry, both ids
  size_t w = 0;
  for (size_t k = 0; k < e.size(); ++k)
    if (w > 0 && e[w - 1].x == e[k].x && e[w - 1].y == e[k].y)
      e[w - 1].w = e[k].z;
    else
      e[w++] = e[k];
  e.resize(w);
  return e;
}

SheetLayout SheetLayout::of(const SheetTopology& topo, VkDeviceSize max_range, bool contact) {
  SheetLayout l;
  l.tear_slots = topo.constraintCount() + topo.triangleCount() + 1;
  l.tear_sums = l.tear_slots;
  l.hash_sums = l.tear_sums + scanSumsSize(l.tear_slots);
  // Collision candidate lists, when the largest binding holds them
  l.candidates_fit = 4ull * SIM_CANDIDATE_STRIDE * topo.particleCount() <= max_range;
  l.contact = contact;
  if (contact) {
    // Each edge once: V - E + F = 1 for a sheet in one piece with no hole, E = V + F - 1 at most
    l.contact_edges = uint32_t(contactEdges(topo).size());
    const uint32_t boxes = topo.triangleCount() + l.contact_edges;
    l.contact_buckets = 2 * std::bit_ceil(std::max(boxes, 16u)); // two halves: triangles, edges
    // After the hash's sums and the fused tick's scan totals (which meet after the compaction slots)
    l.contact_counts = std::max(l.hash_sums + scanSumsSize(topo.hash_size), l.tear_slots + SIM_WG_FUSED_MAX);
    l.contact_fill = l.contact_counts + l.contact_buckets + 1;
    l.contact_sums = l.contact_fill + l.contact_buckets;
    const uint32_t queries = topo.particleCount() + l.contact_edges;
    l.contact_active = l.contact_sums + scanSumsSize(l.contact_buckets + 1);
    l.contact_active_sums = l.contact_active + queries + 1;
    l.contact_half = l.contact_active_sums + scanSumsSize(queries + 1);
    l.contact_half_sums = l.contact_half + 2 * topo.particleCount() + 1;
    // The header, the entries, the boxes and the active queries (contact_grid.glsl)
    l.contact_words = SIM_CONTACT_HEADER + uint64_t(SIM_CONTACT_CELLS_PER_BOX + 6) * boxes + queries;
    // The edges, then the lists' header, where each particle was, each query's count and pairs,
    // then the settle's half-spaces (five words each)
    l.contact_list_words = 4ull * l.contact_edges + SIM_CONTACT_LIST_HEADER + 4ull * topo.particleCount() +
                           uint64_t(1 + SIM_CONTACT_LIST_CAPACITY) * (topo.particleCount() + l.contact_edges) +
                           5ull * SIM_CONTACT_HALF_CAPACITY * topo.particleCount();
  }
  return l;
}

std::vector<BindingSpec> sheetBindings(const SheetTopology& topo, const SheetLayout& layout, StartData& d,
                                       bool particle_data) {
  const uint32_t n = topo.particleCount(), m = topo.constraintCount(), t = topo.triangleCount();
  const uint32_t cells = topo.hash_size;
  // The fused tick's scans meet their per-invocation totals in the SIM_WG_FUSED_MAX slots after the
  // compaction slots (the per-colour passes' block sums, unused on that path).
  const uint32_t scratch = std::max({layout.hash_sums + scanSumsSize(cells), layout.tear_slots + SIM_WG_FUSED_MAX,
                                     layout.contact ? layout.contact_half_sums + scanSumsSize(n + 1) : 0u});
  const VkDeviceSize list_bytes = layout.candidates_fit ? 4ull * SIM_CANDIDATE_STRIDE * n : 16,
                     list_base = layout.candidates_fit ? 16ull * n : 16;

  // Start contents derived from the topology; the per-particle ones only for an upload.
  if (particle_data) {
    d.pos.resize(n);
    for (uint32_t i = 0; i < n; ++i) d.pos[i] = startPosition(topo.rest_pos[i]);
    d.normal.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    d.adj_mask = adjacencyMasks(topo);
  }
  if (layout.contact) d.contact_edges = contactEdges(topo);
  d.last_start = n; // cell_start[T] = N, always
  d.colors.clear();
  for (const ColorRange& c : topo.colors) d.colors.emplace_back(c.first, c.count);
  d.counters = Counters{};
  d.counters.triangle_count = t;
  d.counters.compact_dispatch = uvec4(0u, 1u, 1u, 0u);
  d.counters.draw_args = uvec4(3u * t, 1u, 0u, 0u);

  enum : uint8_t { kPlain = 0, kRestored = 1, kReadBack = 2 };
  auto spec = [](uint32_t binding, VkDeviceSize bytes, const void* data = nullptr, VkDeviceSize data_bytes = 0,
                 uint8_t flags = kPlain, VkDeviceSize offset = 0) {
    return BindingSpec{binding, bytes, data, data_bytes, offset, (flags & kRestored) != 0, (flags & kReadBack) != 0};
  };
  return {
      // Particles
      spec(SIM_BIND_POS, 16ull * n, d.pos.data(), bytesOf(d.pos), kReadBack),
      spec(SIM_BIND_PREV, 16ull * n, d.pos.data(), bytesOf(d.pos), kReadBack),
      spec(SIM_BIND_REST, 16ull * n, topo.rest_pos.data(), bytesOf(topo.rest_pos)),
      spec(SIM_BIND_UV, 8ull * n, topo.uv.data(), bytesOf(topo.uv)),
      spec(SIM_BIND_NORMAL, 16ull * n, d.normal.data(), bytesOf(d.normal), kReadBack),
      spec(SIM_BIND_RESET_FROM, 16ull * n, d.pos.data(), bytesOf(d.pos)),
      spec(SIM_BIND_DELTA, 16ull * n),
      // Constraints and what tearing changes (a reset restores them)
      spec(SIM_BIND_CONSTRAINTS, 16ull * m, topo.constraints.data(), bytesOf(topo.constraints), kRestored | kReadBack),
      spec(SIM_BIND_COLOR_RANGES, 8ull * topo.colorCount(), d.colors.data(), bytesOf(d.colors), kRestored | kReadBack),
      spec(SIM_BIND_TORN, 4ull * m, nullptr, 0, kRestored | kReadBack),
      spec(SIM_BIND_HINGES, 16ull * topo.hingeCount(), nullptr, 0, kRestored | kReadBack),
      spec(SIM_BIND_TRIANGLES, 16ull * t, topo.triangles.data(), bytesOf(topo.triangles), kRestored | kReadBack),
      spec(SIM_BIND_COUNTERS, sizeof(Counters), &d.counters, sizeof(Counters), kRestored | kReadBack),
      spec(SIM_BIND_TRI_EDGES, 8ull * t, topo.tri_edges.data(), bytesOf(topo.tri_edges)),
      spec(SIM_BIND_COMPACT_TMP, 16ull * (m + t)),
      spec(SIM_BIND_SCRATCH, 4ull * scratch),
      // Collision: adjacency, the spatial hash, the candidate lists
      spec(SIM_BIND_ADJ_OFFSETS, 4ull * topo.adj_offsets.size(), topo.adj_offsets.data(), bytesOf(topo.adj_offsets)),
      spec(SIM_BIND_ADJ_LIST, 4ull * topo.adj_list.size(), topo.adj_list.data(), bytesOf(topo.adj_list)),
      spec(SIM_BIND_ADJ_MASK, 4ull * n, d.adj_mask.data(), bytesOf(d.adj_mask)),
      spec(SIM_BIND_CELL_COUNT, 4ull * cells),
      spec(SIM_BIND_CELL_START, 4ull * (cells + 1), &d.last_start, 4, kPlain, 4ull * cells),
      spec(SIM_BIND_CELL_PARTICLES, 4ull * n),
      spec(SIM_BIND_PARTICLE_CELL, 4ull * n),
      spec(SIM_BIND_CELL_SCATTER, 4ull * n),
      spec(SIM_BIND_CELL_POS, 16ull * n),
      spec(SIM_BIND_CANDIDATES, list_bytes),
      spec(SIM_BIND_CANDIDATE_BASE, list_base),
      spec(SIM_BIND_HASH_ARGS, 16ull * SIM_SHEET_ARGS),
      // Interaction
      spec(SIM_BIND_PICK, sizeof(PickResult)),
      // Contact (a word each while it is not sized): the edges, and what a reset clears
      spec(SIM_BIND_CONTACT_LISTS, layout.contact ? 4ull * layout.contact_list_words : 16, d.contact_edges.data(),
           bytesOf(d.contact_edges)),
      spec(SIM_BIND_CONTACT, layout.contact ? sizeof(ContactParticle) * n : 16, nullptr, 0, kRestored),
      spec(SIM_BIND_CONTACT_GRID, layout.contact ? 4ull * layout.contact_words : 16),
  };
}

void assembleState(const SheetTopology& topo, const std::function<const void*(uint32_t binding)>& bytes,
                   SimState& out) {
  auto take = [&]<class T>(uint32_t binding, std::vector<T>& v, size_t count) {
    v.resize(count);
    if (count) std::memcpy(v.data(), bytes(binding), count * sizeof(T));
  };
  const uint32_t n = topo.particleCount(), m = topo.constraintCount();
  take(SIM_BIND_POS, out.pos, n);
  take(SIM_BIND_PREV, out.prev, n);
  take(SIM_BIND_NORMAL, out.normal, n);
  take(SIM_BIND_CONSTRAINTS, out.constraints, m);
  take(SIM_BIND_TORN, out.torn, m);
  take(SIM_BIND_HINGES, out.hinges, topo.hingeCount());
  std::vector<glm::uvec2> colors;
  take(SIM_BIND_COLOR_RANGES, colors, topo.colorCount());
  std::vector<glm::uvec4> triangles;
  take(SIM_BIND_TRIANGLES, triangles, topo.triangleCount());
  Counters counters{};
  std::memcpy(&counters, bytes(SIM_BIND_COUNTERS), sizeof(counters));
  out.colors.resize(colors.size());
  for (size_t c = 0; c < colors.size(); ++c) out.colors[c] = {colors[c].x, colors[c].y};
  out.triangle_count = std::min<uint32_t>(counters.triangle_count, topo.triangleCount());
  out.triangles.assign(triangles.begin(), triangles.begin() + out.triangle_count);
}

} // namespace tender::gpu
