#pragma once
/// A picture of a preset without a window: build the sheet on the chosen backend (sharing the
/// renderer's Vulkan context), run N ticks (optionally replaying an input script), render it
/// offscreen.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "core/params.h"
#include "core/script.h"
#include "render/offscreen.h"

namespace tender::render {

/// What to render.
struct HeadlessOptions {
  SimParams params;
  std::string backend = "gpu"; ///< a createBackend name
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
  std::string device;               ///< the device that drew it (its name)
  std::string error;                ///< empty on success
};

/// Runs the simulation and renders it; a missing device, a Vulkan error or a missing font set
/// `error`.
HeadlessResult renderHeadless(const HeadlessOptions& options);

/// The frames of a sequence (a video): how many, and the ticks run before each.
struct FrameSequence {
  uint64_t frames = 0;
  /// Total ticks run before frame k (0-based); never decreasing. options.ticks is not used.
  std::function<uint64_t(uint64_t frame)> ticks_before;
  /// Takes each frame's picture in order; an error stops the run and is returned.
  std::function<std::optional<std::string>(const Picture& picture, uint64_t frame)> sink;
};

/// Runs the simulation once and renders every frame of the sequence; returns the first error (of
/// Vulkan, the font, or the sink). `validation_messages`, when given, receives their count, and
/// `device` the name of the device.
std::optional<std::string> renderSequence(const HeadlessOptions& options, const FrameSequence& sequence,
                                          uint32_t* validation_messages = nullptr, std::string* device = nullptr);

} // namespace tender::render
