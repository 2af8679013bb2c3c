#pragma once
/// A picture of a preset without a window: build the sheet, run N ticks (optionally replaying an
/// input script), render it offscreen.
#include <cstdint>
#include <string>

#include "core/params.h"
#include "core/script.h"
#include "offscreen.h"

namespace tender::gpu {
class GpuSolver;
}

namespace tender::render {

/// What to render.
struct HeadlessOptions {
  SimParams params;
  std::string backend = "gpu"; ///< cpu or gpu
  int device = -1;             ///< Vulkan device index, -1 = best
  bool validation = false;     ///< VK_LAYER_KHRONOS_validation
  bool quiet = false;          ///< count validation messages without printing them
  InputScript script;
  uint64_t ticks = 0;
  uint32_t width = 1280, height = 720;
};

/// The picture, or a one-line error.
struct HeadlessResult {
  Picture picture;
  uint32_t validation_messages = 0; ///< warnings and errors reported by the validation layers
  std::string error;                ///< empty on success
};

/// The solver's own buffers as the renderer binds them (no copy).
PaperBuffers gpuPaperBuffers(gpu::GpuSolver& solver);

/// Runs the simulation and renders it; a missing device sets `error` (a missing font throws).
HeadlessResult renderHeadless(const HeadlessOptions& options);

} // namespace tender::render
