#pragma once
/// An exact judge of the sheet passing through itself: the pairs of triangles that share no
/// particle and intersect (touching counts), decided with exact orientation predicates (a double
/// filter, then GMP rationals), so the count is the same on every machine and never a rounding's.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace tender {

/// The sign (-1, 0, 1) of the determinant |a - d, b - d, c - d|: positive when d lies below the
/// plane of a, b, c (a, b, c counter-clockwise seen from above). Exact.
int orient3d(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d);
/// The sign (-1, 0, 1) of (a - c) x (b - c) in the plane: positive when a, b, c turn
/// counter-clockwise. Exact.
int orient2d(glm::vec2 a, glm::vec2 b, glm::vec2 c);

/// True when the closed triangles (a0, a1, a2) and (b0, b1, b2) have a point in common. A triangle
/// of no area is judged as its edges; two of no area, never.
bool trianglesIntersect(const glm::vec3 a[3], const glm::vec3 b[3]);

struct IntersectionCount {
  uint64_t pairs = 0;      ///< intersecting pairs of triangles that share no particle
  uint64_t candidates = 0; ///< pairs whose bounding boxes overlap (the exact test's work)
};

/// The intersecting pairs among the first `count` triangles (xyz: their particles) of a sheet at
/// `pos`; pairs that share a particle are neighbours on the sheet and are not counted. With
/// `crossing`, also which triangles intersect another (1), by index.
IntersectionCount intersectingPairs(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles,
                                    uint32_t count, std::vector<uint8_t>* crossing = nullptr);

} // namespace tender
