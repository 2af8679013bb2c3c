#pragma once
/// The sheet's topology and start state, built once on the CPU and shared by both solvers.
#include <array>
#include <cstdint>
#include <vector>

#include "params.h"
#include "shaderio.h"

namespace tender {

/// First constraint and count of one colour (no two constraints of a colour share a particle).
struct ColorRange {
  uint32_t first = 0;
  uint32_t count = 0;
};

/// Everything both solvers upload unchanged.
struct SheetTopology {
  uint32_t cols = 0, rows = 0;
  std::vector<glm::vec4> rest_pos;                    ///< xyz start position, w = 1 for a pin point
  std::vector<glm::vec2> uv;                          ///< receipt texture coordinates
  std::vector<shaderio::Constraint> constraints;      ///< sorted by colour
  std::vector<ColorRange> colors;                     ///< ranges into `constraints`
  std::array<uint32_t, SIM_KIND_COUNT> kind_counts{}; ///< constraints per kind
  uint32_t hinge_first = 0;                           ///< original id of hinge 0 (gridHinge): hinges are the last ids
  std::vector<uint32_t> adj_offsets;                  ///< CSR: neighbours of i are adj_list[adj_offsets[i] .. [i+1])
  std::vector<uint32_t> adj_list;                     ///< sorted ascending per particle
  std::vector<glm::uvec4> triangles;                  ///< xyz vertices (counter-clockwise from +z), w = triangle id
  std::vector<glm::uvec2> tri_edges;                  ///< per triangle id: original ids of its two structural edges
  uint32_t hash_size = 0;                             ///< spatial hash buckets: power of two >= 2N
  bool contact = false; ///< made with contact on: the GPU sizes its contact buffers from the start

  uint32_t particleCount() const { return uint32_t(rest_pos.size()); }
  uint32_t constraintCount() const { return uint32_t(constraints.size()); }
  uint32_t triangleCount() const { return uint32_t(triangles.size()); }
  uint32_t colorCount() const { return uint32_t(colors.size()); }
  uint32_t hingeCount() const { return kind_counts[SIM_KIND_HINGE]; }
  /// True when particles a and b share a constraint in the initial topology.
  bool adjacent(uint32_t a, uint32_t b) const;
};

/// Kind of a packed constraint.
inline uint32_t constraintKind(const shaderio::Constraint& c) { return c.kind_id & SIM_KIND_MASK; }
/// Original id of a packed constraint (index into the torn flags).
inline uint32_t constraintId(const shaderio::Constraint& c) { return c.kind_id >> SIM_KIND_BITS; }

/// Builds particles, constraints (coloured and sorted), adjacency and triangles.
SheetTopology buildSheet(const SimParams& p);

/// Nine particles spread over the sheet (its corners, its edges' middles and its centre): where a
/// camera that follows the sheet reads it.
std::vector<uint32_t> sheetSamples(const SheetTopology& t);

/// Where buildSheet places the sheet: the height of its top edge, and how far its rows go down
/// and back (the tilt) over the sheet's length.
struct SheetPlacement {
  float top = 0.0f;
  float down = 1.0f, back = 0.0f; ///< cos and sin of the tilt
  float length = 0.0f;            ///< (rows - 1) x spacing
};
SheetPlacement sheetPlacement(const SimParams& p);

/// Greedy colouring: colour of each constraint, smallest colour free at every particle it moves
/// (both ends; a hinge's four corners, gridHinge on a `cols` x `rows` grid). Hinges take colours of
/// their own, after the others', so that a colour holds one kind of projection.
std::vector<uint32_t> colorGreedy(const std::vector<shaderio::Constraint>& cs, uint32_t cols, uint32_t rows,
                                  uint32_t hinge_first = ~0u);

/// Stable-sorts constraints by colour and returns the colour ranges.
std::vector<ColorRange> sortByColor(std::vector<shaderio::Constraint>& cs, const std::vector<uint32_t>& color);

/// Indices of the pin points of a W x H sheet.
std::vector<uint32_t> pinIndices(PinMode mode, uint32_t cols, uint32_t rows);

} // namespace tender
