#pragma once
/// What a solver answers from a sheet's positions on the host, the same way everywhere: the
/// nearest particle to a ray (a pick) and the grid normals.
#include <cstdint>
#include <vector>

#include "shaderio.h"

namespace tender {

/// Nearest particle to the ray o + t d (|d| = 1) within radius: the smallest squared distance,
/// the smallest index among equals (as the GPU's pick passes); index SIM_NONE when none is near.
shaderio::PickResult pickNearest(const std::vector<glm::vec4>& pos, glm::vec3 o, glm::vec3 d, float radius);

/// Each particle's normal from its grid neighbours (as the normals pass), w = 0.
void gridNormals(const std::vector<glm::vec4>& pos, uint32_t cols, uint32_t rows, std::vector<glm::vec4>& out);

} // namespace tender
