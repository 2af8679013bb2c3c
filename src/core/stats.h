#pragma once
/// Summary statistics of a state, the `--stats` JSON, and the PLY writer.
#include <array>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "solver.h"

namespace tender {

struct SheetStats {
  uint32_t particles = 0;
  std::array<uint32_t, 4> constraints{}; ///< alive per kind
  uint32_t colors = 0;
  uint32_t torn = 0;
  uint32_t triangles = 0;
  uint64_t state_hash = 0; ///< FNV-1a 64 of the position bytes
  glm::vec3 bbox_min{0.0f}, bbox_max{0.0f};
  float max_stretch = 0.0f; ///< largest length / rest over alive structural constraints
  uint32_t nan_count = 0;   ///< non-finite position components
  float max_speed = 0.0f;   ///< largest |pos - prev| / substep dt
};

/// Names of the constraint kinds, indexed by kind.
const char* kindName(uint32_t kind);
/// FNV-1a 64 of the bytes of the positions.
uint64_t hashPositions(const std::vector<glm::vec4>& pos);
/// Computes the summary of a read-back state.
SheetStats computeStats(const SimState& s, float substep_dt);
/// The stats as JSON (the caller adds timing fields).
nlohmann::json statsJson(const SheetStats& s);
/// Writes a binary PLY with the positions and the live triangles to an open file; false on an
/// I/O error (write it through OutputSet or writeFileAtomically).
bool writePly(std::FILE* f, const SimState& s);

} // namespace tender
