#pragma once
/// Summary statistics of a state, the `--stats` JSON, and the PLY writer.
#include <array>
#include <cstdio>
#include <string>

// The JSON type declared only: what builds or reads the stats JSON includes <nlohmann/json.hpp>,
// and the many tests that only compute stats are spared compiling it.
#include <nlohmann/json_fwd.hpp>

#include "solver.h"

namespace tender {

/// A hinge whose rest angle is this far from flat (degrees) counts as creased.
constexpr float kCreasedDegrees = 2.0f;

struct SheetStats {
  uint32_t particles = 0;
  std::array<uint32_t, SIM_KIND_COUNT> constraints{}; ///< alive per kind
  uint32_t colors = 0;
  uint32_t torn = 0;
  uint32_t triangles = 0;
  uint32_t creased = 0;        ///< hinges whose rest angle is more than kCreasedDegrees from flat
  float max_crease_deg = 0.0f; ///< largest |rest angle| of a hinge, degrees
  uint64_t state_hash = 0;     ///< FNV-1a 64 of the position bytes
  glm::vec3 bbox_min{0.0f}, bbox_max{0.0f};
  float max_stretch = 0.0f; ///< largest length / rest over alive structural constraints
  uint32_t nan_count = 0;   ///< non-finite position components
  float max_speed = 0.0f;   ///< largest |pos - prev| / substep dt
  /// Pairs of triangles that share no particle and intersect (intersectingPairs): where the sheet
  /// has passed through itself; -1 until judged (judgeIntersections)
  int64_t pairs = -1;
};

/// Names of the constraint kinds, indexed by kind.
const char* kindName(uint32_t kind);
/// FNV-1a 64 of `size` bytes, continuing from `h` (the offset basis: a hash of nothing).
uint64_t fnv1a(const void* data, size_t size, uint64_t h = 1469598103934665603ull);
/// FNV-1a 64 of the bytes of the positions.
uint64_t hashPositions(const std::vector<glm::vec4>& pos);
/// Computes the summary of a read-back state.
SheetStats computeStats(const SimState& s, float substep_dt);
/// Judges the state's triangles for the sheet passing through itself (SheetStats::pairs).
void judgeIntersections(SheetStats& st, const SimState& s);
/// The stats as JSON (the caller adds timing fields).
nlohmann::json statsJson(const SheetStats& s);
/// A 64-bit hash as the 16 hex digits the stats print.
std::string hashHex(uint64_t h);

/// What a run adds to the stats: its preset, ticks and the wall time of each physics tick (ms).
struct RunRecord {
  std::string preset;
  uint64_t ticks = 0, physics_ticks = 0;
  std::vector<double> tick_ms;
};
/// The stats JSON of a run (`tender sim --stats`, the Python module's stats()): statsJson plus the
/// run's preset, backend, ticks, median and slowest tick, dispatches, arithmetic and, on the GPU,
/// the time of each pass. `median_ms`, when given, receives the median.
nlohmann::json runStatsJson(const SheetStats& s, const Solver& solver, RunRecord run, bool gpu,
                            double* median_ms = nullptr, double* slowest_ms = nullptr);
/// Writes a binary PLY with the positions and the live triangles to an open file; false on an
/// I/O error (write it through OutputSet or writeFileAtomically).
bool writePly(std::FILE* f, const SimState& s);

} // namespace tender
