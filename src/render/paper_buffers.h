#pragma once
/// What every render pass reads: the scene uniforms (shared with GLSL) and the buffers the paper
/// is drawn from.
#include <cstddef>

#include <glm/glm.hpp>

#include "gpu/context.h"

namespace shaderio {
using namespace glm;
#include "render_types.h"
static_assert(sizeof(SceneUniforms) == 2 * 64 + 8 * 16);
static_assert(offsetof(SceneUniforms, eye) == 128);
static_assert(offsetof(SceneUniforms, floor) == 128 + 7 * 16);
} // namespace shaderio

namespace tender::render {

/// The buffers the paper is drawn from: the solver's arrays (vertex pulling) and the indirect
/// draw arguments of the live triangles (three vertices each).
struct PaperBuffers {
  VkBuffer pos = VK_NULL_HANDLE;       ///< vec4 per particle
  VkBuffer normal = VK_NULL_HANDLE;    ///< vec4 per particle
  VkBuffer uv = VK_NULL_HANDLE;        ///< vec2 per particle
  VkBuffer triangles = VK_NULL_HANDLE; ///< uvec4 per triangle (xyz = particle indices)
  VkBuffer draw_args = VK_NULL_HANDLE; ///< VkDrawIndirectCommand
  VkDeviceSize draw_args_offset = 0;
};

} // namespace tender::render
