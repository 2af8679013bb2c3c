#pragma once
/// The SPIR-V embedded at build time (shaders/CMakeLists.txt), looked up by file stem.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace tender::gpu {

/// SPIR-V of shaders/sim/<key>.glsl ("integrate.comp"), or an empty span.
std::span<const uint32_t> simShader(std::string_view key);
/// Keys of every shader of shaders/sim.
std::vector<std::string_view> simShaderKeys();
/// SPIR-V of shaders/render/<key>.glsl ("paper.vert"), or an empty span (link tender_render_shaders).
std::span<const uint32_t> renderShader(std::string_view key);
std::vector<std::string_view> renderShaderKeys();

} // namespace tender::gpu
