#include "cpu_collision.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "simd_kernels.h"
#include "worker_pool.h"

namespace tender {

using namespace shaderio;

bool gatherReference(const GatherArrays& g, const SimUniforms& u, uint32_t begin, uint32_t end, float search,
                     bool build) {
  const float r = u.collision_radius, search2 = search * search;
  bool fits = true;
  for (uint32_t k = begin; k < end; ++k) {
    const uint32_t i = g.particle[k];
    const vec3 pi(g.x[k], g.y[k], g.z[k]);
    const ivec3 ci(g.cell[k]);
    const uint32_t *adj = g.adj_list + g.adj_offsets[i], *adj_end = g.adj_list + g.adj_offsets[i + 1];
    uint32_t* candidates = build ? g.candidates + size_t(SIM_CANDIDATE_STRIDE) * i : nullptr;
    uint32_t found = 0;
    vec3 sum(0.0f);
    // The 27 cells in cellCode order; each bucket's particles that lie in that very cell.
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const ivec3 c = ci + ivec3(dx, dy, dz);
          const uint32_t h = hashCell(c, u.hash_mask);
          for (uint32_t m = g.cell_start[h]; m < g.cell_start[h + 1]; ++m) {
            const uint32_t j = g.particle[m];
            if (m == k || ivec3(g.cell[m]) != c || std::binary_search(adj, adj_end, j)) continue;
            const vec3 pj(g.x[m], g.y[m], g.z[m]);
            // Candidate list: insert j in order, while it has room; count every candidate.
            const vec3 d = pi - pj;
            if (candidates && dot3(d, d) < search2) found = addCandidate(candidates, found, j);
            sum += repulsion(pi, pj, r, u.collision_stiffness);
          }
        }
    fits = endGather(g, k, i, pi, sum, candidates, found) && fits;
  }
  return fits;
}

CpuCollision::CpuCollision(WorkerPool& pool, bool simd, bool candidates)
    : pool_(pool), simd_(simd && simd::kBuilt), candidates_enabled_(candidates) {}

void CpuCollision::upload(const std::vector<uint32_t>& adj_offsets, const std::vector<uint32_t>& adj_list,
                          uint32_t hash_size, Grain grain) {
  const uint32_t n = uint32_t(adj_offsets.size()) - 1;
  grain_ = grain;
  adj_offsets_ = adj_offsets;
  adj_list_ = adj_list;
  adj_list_.resize(adj_list_.size() + kAdjacencyPad, ~0u);
  cell_count_.assign(hash_size, 0u);
  cell_start_.assign(hash_size + 1, 0u);
  cell_particles_.assign(n, 0u);
  particle_slot_.assign(n, 0u);
  particle_cell_.assign(n, 0u);
  particle_coord_.assign(n, ivec4(0));
  sorted_x_.assign(n + kSortedPad, 0.0f);
  sorted_y_.assign(n + kSortedPad, 0.0f);
  sorted_z_.assign(n + kSortedPad, 0.0f);
  sorted_coord_.assign(n, ivec4(0));
  delta_.assign(n, vec4(0.0f));
  delta_by_particle_ = false;
  candidates_.assign(candidates_enabled_ ? size_t(SIM_CANDIDATE_STRIDE) * n : 0, 0u);
  candidate_base_.assign(candidates_enabled_ ? n : 0, vec3(0.0f));
  candidate_state_ = uvec4(0u);
}

void CpuCollision::buildHash(const SimUniforms& u, const vec4* pos) {
  const uint32_t n = uint32_t(cell_particles_.size());
  const uint32_t g = grain_(kGrainParticles);
  // Cell and bucket of every particle
  pool_.parallelFor(n, g, [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      const ivec3 c = cellOf(vec3(pos[i]), u.inv_cell);
      particle_coord_[i] = ivec4(c, 0);
      particle_cell_[i] = hashCell(c, u.hash_mask);
    }
  });
  // Count (the counts are all zero here: the scan clears them)
  uint32_t* count = cell_count_.data();
  const uint32_t* cell = particle_cell_.data();
  for (uint32_t i = 0; i < n; ++i) count[cell[i]]++;
  // Exclusive scan, shifted by one: start[h + 1] is the scatter's cursor in bucket h, and ends as
  // the start of bucket h + 1.
  uint32_t sum = 0;
  uint32_t* start = cell_start_.data();
  start[0] = 0;
  for (size_t h = 0, buckets = cell_count_.size(); h < buckets; ++h) {
    start[h + 1] = sum;
    sum += count[h];
    count[h] = 0;
  }
  // Scatter in index order, so the particles of a bucket stay sorted by index
  uint32_t *sorted = cell_particles_.data(), *slot = particle_slot_.data();
  for (uint32_t i = 0; i < n; ++i) {
    slot[i] = start[cell[i] + 1]++;
    sorted[slot[i]] = i;
  }
  // Gather positions and cells in bucket order, for the gather
  pool_.parallelFor(n, g, [&](uint32_t begin, uint32_t end) {
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t j = cell_particles_[k];
      sorted_x_[k] = pos[j].x;
      sorted_y_[k] = pos[j].y;
      sorted_z_[k] = pos[j].z;
      sorted_coord_[k] = particle_coord_[j];
    }
  });
}

GatherArrays CpuCollision::arrays() {
  GatherArrays g;
  g.x = sorted_x_.data();
  g.y = sorted_y_.data();
  g.z = sorted_z_.data();
  g.cell = sorted_coord_.data();
  g.particle = cell_particles_.data();
  g.cell_start = cell_start_.data();
  g.adj_offsets = adj_offsets_.data();
  g.adj_list = adj_list_.data();
  g.delta = delta_.data();
  g.candidates = candidates_.data();
  g.candidate_base = candidate_base_.data();
  return g;
}

bool CpuCollision::gatherRange(const SimUniforms& u, uint32_t begin, uint32_t end, float search, bool build) {
  const GatherArrays g = arrays();
  return simd_ ? simd::gather(g, u, begin, end, search, build) : gatherReference(g, u, begin, end, search, build);
}

bool CpuCollision::gather(const SimUniforms& u, float search, bool build) {
  std::atomic<bool> overflow{false};
  pool_.parallelFor(
      uint32_t(cell_particles_.size()), grain_(kGrainCollide),
      [&](uint32_t begin, uint32_t end) {
        if (!gatherRange(u, begin, end, search, build)) overflow.store(true, std::memory_order_relaxed);
      },
      kCollideChunksPerWorker);
  delta_by_particle_ = false;
  return !overflow.load();
}

// Repulsion on particle i from its candidate list: the candidates closer than the radius, summed as
// the gather sums them, by neighbour cell and then by index (the list is ascending).
vec3 CpuCollision::candidateRepulsion(const SimUniforms& u, const vec4* pos, uint32_t i) const {
  const uint32_t* candidates = candidates_.data() + size_t(SIM_CANDIDATE_STRIDE) * i;
  const uint32_t count = candidates[0];
  vec3 sum(0.0f);
  if (count == 0) return sum;
  const float r = u.collision_radius, r2 = r * r;
  const vec3 pi(pos[i]);
  const ivec3 ci = cellOf(pi, u.inv_cell);
  uint32_t code[SIM_CANDIDATE_CAPACITY]; // neighbour cell of each candidate within the radius; 27: none
  for (uint32_t e = 0; e < count; ++e) {
    const vec3 pj(pos[candidates[e + 1]]);
    const vec3 d = pi - pj;
    const ivec3 o = cellOf(pj, u.inv_cell) - ci;
    const bool in_reach = dot3(d, d) < r2 && std::abs(o.x) <= 1 && std::abs(o.y) <= 1 && std::abs(o.z) <= 1;
    code[e] = in_reach ? cellCode(o) : 27u;
  }
  for (uint32_t b = 0; b < 27; ++b)
    for (uint32_t e = 0; e < count; ++e)
      if (code[e] == b) sum += repulsion(pi, vec3(pos[candidates[e + 1]]), r, u.collision_stiffness);
  return sum;
}

uint32_t CpuCollision::substep(const SimUniforms& u, const vec4* pos) {
  const uint32_t n = uint32_t(cell_particles_.size());
  const float skin = candidates_enabled_ ? candidateSkin(u.collision_radius, u.inv_cell) : 0.0f;
  const float search = u.collision_radius + skin;
  // Has a particle travelled too far for the lists?
  std::atomic<bool> travelled{false};
  if (candidatesCurrent(candidate_state_, skin, search)) {
    pool_.parallelFor(n, grain_(kGrainParticles), [&](uint32_t begin, uint32_t end) {
      bool far = false;
      for (uint32_t i = begin; i < end; ++i) far = far || travelledTooFar(vec3(pos[i]), candidate_base_[i], skin);
      if (far) travelled.store(true, std::memory_order_relaxed);
    });
  }
  const uint32_t mode = collideMode(candidate_state_, travelled.load(), skin, search);
  bool fits = true;
  if (mode == SIM_COLLIDE_CANDIDATES) {
    // Mostly empty lists: a few ns per particle, shared out like the per-particle passes
    pool_.parallelFor(
        n, grain_(kGrainParticles),
        [&](uint32_t begin, uint32_t end) {
          for (uint32_t i = begin; i < end; ++i) delta_[i] = vec4(candidateRepulsion(u, pos, i), 0.0f);
        },
        kCollideChunksPerWorker);
    delta_by_particle_ = true;
  } else {
    buildHash(u, pos);
    const bool build = mode == SIM_COLLIDE_BUILD;
    fits = gather(u, build ? search : u.collision_radius, build);
  }
  candidate_state_ = candidatesNextState(candidate_state_, mode, !fits, search);
  return mode;
}

uint64_t CpuCollision::memoryBytes() const {
  return capacityBytes(adj_offsets_) + capacityBytes(adj_list_) + capacityBytes(cell_count_) +
         capacityBytes(cell_start_) + capacityBytes(cell_particles_) + capacityBytes(particle_cell_) +
         capacityBytes(particle_slot_) + capacityBytes(particle_coord_) + capacityBytes(sorted_x_) +
         capacityBytes(sorted_y_) + capacityBytes(sorted_z_) + capacityBytes(sorted_coord_) + capacityBytes(delta_) +
         capacityBytes(candidates_) + capacityBytes(candidate_base_);
}

} // namespace tender
