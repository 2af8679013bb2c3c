#pragma once
/// The HUD over the scene (Dear ImGui): the spec's title, instruction line, controls hint, FPS,
/// "Initialising…" progress, "PAUSED" overlay, buttons, and a parameter panel.
#include <optional>
#include <string>

#include "core/params.h"
#include "core/solver.h"
#include "shaderio.h"

struct ImFont;
struct ImVec2;

namespace tender::demo {

/// What the HUD shows this frame.
struct HudState {
  float init_progress = 1.0f; ///< pipelines built, 0..1 (< 1: "Initialising…")
  float init_alpha = 0.0f;    ///< opacity of "Initialising…" (fades out once the simulation starts)
  double seconds = 0.0;       ///< since the simulation started
  float fps = 0.0f;
  bool show_fps = false, paused = false, wind = true, pins = true;
  bool follow = false; ///< the camera follows a tossed sheet
  std::string device;  ///< renderer device name
  std::string notice;  ///< how the demo runs on this device, when it runs differently (a CPU device)
  const PassTimes* times = nullptr;
  uint32_t triangles = 0; ///< live triangles (0 when unknown)
  /// Where the grab holds the paper, in window pixels, while grabbing: the hand sprite's place
  std::optional<glm::vec2> grab_point;
  float closure = 0.0f; ///< the hand around the grab: 0 open .. 1 closed (its fingers curl)
};

/// What the user asked for through the HUD this frame.
struct HudActions {
  bool toggle_wind = false, reset = false, toggle_pins = false, toggle_pause = false;
  bool reset_view = false;           ///< the camera back to the start view
  bool toggle_follow = false;        ///< the camera follow on or off
  bool live_changed = false;         ///< `params` changed in ways that need no rebuild
  bool rebuild = false;              ///< `params` needs a rebuild (grid size)
  std::optional<std::string> preset; ///< switch to this preset
};

/// Draws the HUD with Dear ImGui (the ImGui context must exist).
class Hud {
public:
  /// Loads the TTF fonts at this UI scale (call before the font atlas is uploaded).
  explicit Hud(float scale);
  /// Draws the HUD; `params` is the panel's working copy of the parameters.
  HudActions draw(const HudState& state, SimParams& params);

private:
  void drawLoading(const HudState& s, const SimParams& params);
  /// FPS top-right, the device notice top-left.
  void drawCorners(const HudState& s);
  /// The buttons' row, bottom-right; gives its window's position.
  ImVec2 drawButtons(const HudState& s, HudActions& a);
  /// The controls hint and the instruction line, clear of the buttons.
  void drawHints(const HudState& s, const SimParams& params, ImVec2 buttons);
  void drawPanel(const HudState& s, SimParams& params, HudActions& a);
  static void passTimes(const PassTimes& times);

  float scale_ = 1.0f;
  ImFont* body_ = nullptr;
  ImFont* title_ = nullptr;
  ImFont* big_ = nullptr;
  std::string instruction_;
};

} // namespace tender::demo
