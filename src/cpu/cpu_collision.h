#pragma once
/// Self-collision of the CPU solver: the spatial hash, the gather over the 27 cells around each
/// particle, and the candidate lists (SIM_CANDIDATE_* in sim_config.h) that stand in for both while no
/// particle has travelled far since they were built. The results are the same either way.
#include <cstdint>
#include <vector>

#include "grain.h"
#include "shaderio.h"

namespace tender {

class WorkerPool;

/// Bytes of host memory a vector holds (its capacity).
template <typename T>
uint64_t capacityBytes(const std::vector<T>& v) {
  return uint64_t(v.capacity()) * sizeof(T);
}

/// Extra entries after the positions in hash order and after the adjacency list, so that 4-wide
/// loads never leave them.
inline constexpr uint32_t kSortedPad = 4, kAdjacencyPad = 16;

/// What one collision gather reads and writes. Slots are the hash order: slot k holds particle
/// particle[k], the particles of a bucket in ascending index.
struct GatherArrays {
  const float* x = nullptr; ///< positions of the slots (x, y, z apart), kSortedPad entries past the end
  const float* y = nullptr;
  const float* z = nullptr;
  const glm::ivec4* cell = nullptr;      ///< integer cell of each slot
  const uint32_t* particle = nullptr;    ///< particle in each slot
  const uint32_t* cell_start = nullptr;  ///< first slot of each bucket, then the end of the last
  const uint32_t* adj_offsets = nullptr; ///< CSR adjacency: particle i's neighbours at [offsets[i], offsets[i + 1])
  const uint32_t* adj_list = nullptr;    ///< ascending per particle, then kAdjacencyPad entries of ~0u
  glm::vec4* delta = nullptr;            ///< out: the repulsion summed on each slot
  uint32_t* candidates = nullptr;        ///< out when building: SIM_CANDIDATE_STRIDE words per particle
  glm::vec3* candidate_base = nullptr;   ///< out when building: where each particle was
};

/// Adds particle j to the candidate list being built at `list` (`found` candidates so far),
/// keeping the list ascending while it has room; returns the new count (a count over
/// SIM_CANDIDATE_CAPACITY means the list overflowed).
inline uint32_t addCandidate(uint32_t* list, uint32_t found, uint32_t j) {
  if (found < SIM_CANDIDATE_CAPACITY) {
    uint32_t e = found + 1;
    for (; e > 1 && list[e - 1] > j; --e) list[e] = list[e - 1];
    list[e] = j;
  }
  return found + 1;
}

/// Ends the gather of slot k (particle i at pi): its delta and, when building (`list` set), the
/// list's count (0 when it overflowed) and base. Returns false when the list overflowed.
inline bool endGather(const GatherArrays& g, uint32_t k, uint32_t i, glm::vec3 pi, glm::vec3 sum, uint32_t* list,
                      uint32_t found) {
  g.delta[k] = glm::vec4(sum, 0.0f);
  if (!list) return true;
  list[0] = found <= SIM_CANDIDATE_CAPACITY ? found : 0u;
  g.candidate_base[i] = pi;
  return found <= SIM_CANDIDATE_CAPACITY;
}

/// The collision gather of hash slots [begin, end), the reference: each particle sums the
/// repulsion of the particles not connected to it in its 27 neighbour cells, cells in dz, dy, dx
/// order (cellCode), the particles of a cell in ascending index, as the GPU sums them. With
/// `build`, the unconnected particles closer than `search` (at least the radius) also go to its
/// candidate list, ascending. Returns false when a candidate list outgrew SIM_CANDIDATE_CAPACITY.
bool gatherReference(const GatherArrays& g, const shaderio::SimUniforms& u, uint32_t begin, uint32_t end, float search,
                     bool build);

/// The collision state and passes of the CPU solver: spatial hash, 27-cell gather, candidate lists.
class CpuCollision {
public:
  /// A collision on `pool`; `simd` gathers with the SIMD kernel (the same bits as the reference),
  /// `candidates` keeps candidate lists.
  CpuCollision(WorkerPool& pool, bool simd, bool candidates);

  /// Sizes every array for a sheet with this adjacency and hash size; the candidate lists start
  /// unusable.
  void upload(const std::vector<uint32_t>& adj_offsets, const std::vector<uint32_t>& adj_list, uint32_t hash_size,
              Grain grain);
  /// Rebuilds the spatial hash: count, scan, scatter (the particles of a bucket in index order),
  /// then gathers positions and cells in that order for the gather.
  void buildHash(const shaderio::SimUniforms& u, const glm::vec4* pos);
  /// Gathers repulsion into the deltas (Jacobi, per hash slot) within the radius, and with `build`
  /// the candidate lists within `search`; needs buildHash. False when a candidate list overflowed.
  bool gather(const shaderio::SimUniforms& u, float search, bool build);
  /// The collision of one substep: from the candidate lists when they hold every pair that can
  /// touch, else buildHash and the gather, which rebuilds the lists unless they were outgrown too
  /// fast of late. Returns the mode (SIM_CANDIDATE_*).
  uint32_t substep(const shaderio::SimUniforms& u, const glm::vec4* pos);
  /// Collision delta of particle i from the last gather or candidate sum.
  glm::vec3 delta(uint32_t i) const { return glm::vec3(delta_[delta_by_particle_ ? i : particle_slot_[i]]); }

  /// True when candidate lists are kept.
  bool keepsCandidates() const { return candidates_enabled_; }
  /// First hash slot of each bucket, then the end (for tests).
  const std::vector<uint32_t>& cellStart() const { return cell_start_; }
  /// Particle in each hash slot (for tests).
  const std::vector<uint32_t>& cellParticles() const { return cell_particles_; }
  /// Deltas of the last gather, per hash slot (for tests).
  const std::vector<glm::vec4>& slotDeltas() const { return delta_; }
  /// Candidate lists, SIM_CANDIDATE_STRIDE words per particle: the count, then ascending particles.
  const std::vector<uint32_t>& candidates() const { return candidates_; }
  /// Positions the candidate lists were built at.
  const std::vector<glm::vec3>& candidateBase() const { return candidate_base_; }
  /// The candidate lists' state (as the GPU's Counters::candidate_state): x usable, y age, z wait, w search bits.
  glm::uvec4 candidateState() const { return candidate_state_; }
  /// What a gather reads and writes.
  GatherArrays arrays();
  /// Bytes of host memory of the collision's arrays (capacity, not size).
  uint64_t memoryBytes() const;

private:
  bool gatherRange(const shaderio::SimUniforms& u, uint32_t begin, uint32_t end, float search, bool build);
  glm::vec3 candidateRepulsion(const shaderio::SimUniforms& u, const glm::vec4* pos, uint32_t i) const;

  WorkerPool& pool_;
  bool simd_;
  bool candidates_enabled_;
  Grain grain_;
  std::vector<uint32_t> adj_offsets_, adj_list_; // CSR adjacency (the list padded)
  std::vector<uint32_t> cell_count_, cell_start_, cell_particles_, particle_cell_;
  std::vector<uint32_t> particle_slot_;               // hash slot of each particle (cell_particles_ inverted)
  std::vector<glm::ivec4> particle_coord_;            // integer cell of each particle
  std::vector<float> sorted_x_, sorted_y_, sorted_z_; // positions in hash order (padded)
  std::vector<glm::ivec4> sorted_coord_;              // cells in hash order
  std::vector<glm::vec4> delta_;                      // collision delta of each hash slot, or particle
  bool delta_by_particle_ = false;                    // delta_ indexed by particle (candidate sums)
  std::vector<uint32_t> candidates_;                  // candidate lists, SIM_CANDIDATE_STRIDE words per particle
  std::vector<glm::vec3> candidate_base_;             // positions the lists were built at
  glm::uvec4 candidate_state_{0u};                    // x usable, y age, z wait, w search bits
};

} // namespace tender
