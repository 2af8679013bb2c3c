#pragma once
/// How finely the CPU solver's passes share their loops out over the worker pool.
#include <cstdint>

namespace tender {

// Smallest share of a loop worth handing to another thread (elements). Below it the hand-off
// (about a microsecond) costs more than the work saved.
inline constexpr uint32_t kGrainParticles = 4096;   ///< integrate, floor, hash, reset: a few ns per particle
inline constexpr uint32_t kGrainConstraints = 1024; ///< projection of one colour, tear marking: ~2 ns each
inline constexpr uint32_t kGrainCollide = 256;      ///< collision gather: ~100 ns per particle
inline constexpr uint32_t kGrainRepair = 32;        ///< a contact list repair's search: ~1 us per primitive
inline constexpr uint32_t kGrainSettle = 256;       ///< the settle's sweeps: ~15 ns per edge
/// Shares per worker of the collision loops: the cost of a particle varies with the crowd around it.
inline constexpr uint32_t kCollideChunksPerWorker = 4;
/// Below this many particles a substep without contact takes tens of microseconds, and sharing its
/// loops costs more in hand-offs than it saves: they run on the calling thread (Grain::heavy's
/// loops, contact's, are shared still).
inline constexpr uint32_t kSmallSheet = 4096;

/// The smallest loop share worth a thread.
struct Grain {
  uint32_t min_chunk = 0;   ///< when set (CpuOptions::min_chunk), the share of every loop
  bool small_sheet = false; ///< no sharing but the heavy loops': the sheet is too small to pay for the hand-offs

  /// The share of a loop whose tuned share is `tuned` elements.
  uint32_t operator()(uint32_t tuned) const { return min_chunk ? min_chunk : small_sheet ? ~0u : tuned; }
  /// The share of a loop that costs enough to share on a small sheet too (contact's).
  uint32_t heavy(uint32_t tuned) const { return min_chunk ? min_chunk : tuned; }
};

} // namespace tender
