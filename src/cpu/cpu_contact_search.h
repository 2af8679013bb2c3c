#pragma once
/// The tests of the CPU contact's pair lists (cpu_contact_lists.cpp) and crossing check
/// (cpu_contact.cpp): the separating axes that part most neighbours before their exact distance.
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "shaderio.h"

namespace tender::contact_search {

using shaderio::dot3;
using shaderio::orderedFloat;

inline float length2(glm::vec3 a) { return dot3(a, a); }

/// How much wider than the reach the separating axes below look, so that a pair they part lies
/// beyond the reach however the exact distance rounds.
inline constexpr float kApartSlack = 1e-3f;

/// True when the segments with midpoints m1, m2 along d1, d2 (end less start) lie farther apart
/// than `reach` on a separating axis, the line through the midpoints or the common normal (the
/// distance of two shapes is at least the gap between their shadows on any line). Most pairs of a
/// crumpled sheet's edges whose boxes meet are neighbours of the sheet a few edges apart, which
/// these part.
inline bool segmentsApart(glm::vec3 m1, glm::vec3 d1, glm::vec3 m2, glm::vec3 d2, float reach) {
  const float wide = reach * (1.0f + kApartSlack);
  const glm::vec3 c = m2 - m1;
  const float l2 = dot3(c, c), shadows = 0.5f * (std::abs(dot3(d1, c)) + std::abs(dot3(d2, c)));
  if (l2 - shadows > wide * std::sqrt(l2)) return true;
  const glm::vec3 n = glm::cross(d1, d2);
  const float g = dot3(c, n);
  return g * g > wide * wide * dot3(n, n);
}

/// True when the balls around two triangles' centroids (radius: to their farthest corners) lie
/// farther apart than `reach`: ball.xyz the centroid, ball.w the radius.
inline bool ballsApart(glm::vec4 a, glm::vec4 b, float reach) {
  const float apart = (a.w + b.w + reach) * (1.0f + kApartSlack);
  return length2(glm::vec3(a) - glm::vec3(b)) > apart * apart;
}

/// The corner of a box whose components are gathered as orderedBits.
inline glm::vec3 orderedCorner(glm::uvec3 o) {
  return glm::vec3(orderedFloat(o.x), orderedFloat(o.y), orderedFloat(o.z));
}

inline bool less4(glm::uvec4 a, glm::uvec4 b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  if (a.z != b.z) return a.z < b.z;
  return a.w < b.w;
}

} // namespace tender::contact_search
