#include "hud.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include <imgui.h>

namespace tender::demo {
namespace {

constexpr const char* kSans = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
constexpr const char* kSansBold = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";
// Seconds before the instruction line fades, and the fade's length.
constexpr double kInstructionSeconds = 4.0;
constexpr double kCrumpleInstructionSeconds = 3.0;
constexpr double kFadeSeconds = 1.0;

ImU32 rgba(uint32_t rgb, float alpha = 1.0f) {
  return IM_COL32((rgb >> 16) & 255, (rgb >> 8) & 255, rgb & 255, int(std::lround(alpha * 255.0f)));
}

// Latin-1 plus the punctuation the HUD prints (em dash, ellipsis).
const ImWchar* glyphRanges() {
  static const ImWchar ranges[] = {0x0020, 0x00FF, 0x2014, 0x2014, 0x2026, 0x2026, 0};
  return ranges;
}

void textAt(ImDrawList* dl, ImFont* font, float size, ImVec2 pos, ImU32 color, const char* text) {
  dl->AddText(font, size, pos, color, text);
}

} // namespace

Hud::Hud(float scale) : scale_(scale) {
  ImGuiIO& io = ImGui::GetIO();
  for (const char* f : {kSans, kSansBold})
    if (!std::filesystem::exists(f))
      throw std::runtime_error(std::string("cannot load the HUD font '") + f + "' (install fonts-dejavu-core)");
  body_ = io.Fonts->AddFontFromFileTTF(kSans, 15.0f * scale, nullptr, glyphRanges());
  title_ = io.Fonts->AddFontFromFileTTF(kSansBold, 20.0f * scale, nullptr, glyphRanges());
  big_ = io.Fonts->AddFontFromFileTTF(kSansBold, 44.0f * scale, nullptr, glyphRanges());
  io.FontDefault = body_;
  ImGui::StyleColorsLight();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 6.0f;
  style.FrameRounding = 4.0f;
  style.Colors[ImGuiCol_WindowBg].w = 0.88f;
  style.ScaleAllSizes(scale);
}

namespace {

// A hand sprite of size `u` (about a finger's length) with its fingertips at `p`, its fingers
// curled into the palm as it closes (closure 0 open .. 1 a fist).
void drawHand(ImDrawList* dl, ImVec2 p, float u, float closure) {
  const ImU32 fill = IM_COL32(255, 236, 214, 235), line = IM_COL32(90, 70, 60, 255);
  const float fw = 0.42f * u; // finger width
  ImVec2 palm_min{p.x - 1.0f * u, p.y + 0.9f * u}, palm_max{p.x + 0.9f * u, p.y + 2.2f * u};
  for (int k = 0; k < 4; ++k) {
    const float x = p.x - 0.95f * u + float(k) * 0.47f * u,
                top = p.y + (k == 1 ? 0.0f : 0.25f * u) + closure * 0.8f * u;
    dl->AddRectFilled({x, top}, {x + fw, palm_min.y + 0.3f * u}, fill, fw * 0.5f);
    dl->AddRect({x, top}, {x + fw, palm_min.y + 0.3f * u}, line, fw * 0.5f, 0, 1.2f);
  }
  dl->AddRectFilled(palm_min, palm_max, fill, 0.35f * u);
  dl->AddRect(palm_min, palm_max, line, 0.35f * u, 0, 1.2f);
  const ImVec2 thumb[4] = {{palm_min.x, palm_min.y + 0.5f * u},
                           {palm_min.x - 0.6f * u, palm_min.y + 0.1f * u},
                           {palm_min.x - 0.75f * u, palm_min.y + 0.35f * u},
                           {palm_min.x, palm_min.y + 1.0f * u}};
  dl->AddConvexPolyFilled(thumb, 4, fill);
  dl->AddPolyline(thumb, 4, line, 0, 1.2f);
}

} // namespace

HudActions Hud::draw(const HudState& s, SimParams& params) {
  HudActions a;
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  const float m = 20.0f * scale_;
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  // Title, top-left: 20 px semibold #444.
  textAt(dl, title_, title_->FontSize, {m, m * 0.8f}, rgba(0x444444), "Tender");
  if (s.init_alpha > 0.0f) drawLoading(s, params);
  if (s.init_progress < 1.0f) return a;
  drawCorners(s);
  const ImVec2 buttons = drawButtons(s, a);
  drawHints(s, params, buttons);
  drawPanel(s, params, a);
  // While grabbing: a small hand at the grab point (palm, four fingers, a thumb)
  if (s.grab_point)
    drawHand(ImGui::GetForegroundDrawList(), {s.grab_point->x, s.grab_point->y}, 9.0f * scale_, s.closure);
  // Paused: 50% overlay with "PAUSED" centred.
  if (s.paused) {
    ImDrawList* fg = ImGui::GetForegroundDrawList();
    fg->AddRectFilled({0.0f, 0.0f}, size, rgba(0x000000, 0.5f));
    ImVec2 ts = big_->CalcTextSizeA(big_->FontSize, FLT_MAX, 0.0f, "PAUSED");
    fg->AddText(big_, big_->FontSize, {(size.x - ts.x) * 0.5f, (size.y - ts.y) * 0.5f}, rgba(0xffffff), "PAUSED");
  }
  return a;
}

void Hud::drawLoading(const HudState& s, const SimParams& params) {
  // Loading: "Initialising…" centred with a progress bar, fading out once the simulation runs.
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  ImDrawList* fg = ImGui::GetForegroundDrawList();
  const float al = s.init_alpha;
  // The crumple page's words; the tender page's otherwise
  const bool crumple = params.release == ReleaseMode::DragVelocity;
  const char* text = crumple ? "Initializing receipt paper\xe2\x80\xa6" : "Initialising\xe2\x80\xa6";
  ImVec2 ts = title_->CalcTextSizeA(title_->FontSize, FLT_MAX, 0.0f, text);
  ImVec2 c{size.x * 0.5f, size.y * 0.5f};
  fg->AddRectFilled({0.0f, 0.0f}, size, rgba(0xe4e0dc, al));
  fg->AddText(title_, title_->FontSize, {c.x - ts.x * 0.5f, c.y - ts.y - 8.0f * scale_}, rgba(0x444444, al), text);
  float w = 220.0f * scale_, h = 6.0f * scale_;
  fg->AddRectFilled({c.x - w * 0.5f, c.y}, {c.x + w * 0.5f, c.y + h}, rgba(0x000000, 0.12f * al), h);
  fg->AddRectFilled({c.x - w * 0.5f, c.y}, {c.x - w * 0.5f + w * s.init_progress, c.y + h}, rgba(0x444444, al), h);
}

void Hud::drawCorners(const HudState& s) {
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  const float m = 20.0f * scale_, body = body_->FontSize;
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  // FPS, top-right, hidden until I.
  if (s.show_fps) {
    char fps[32];
    std::snprintf(fps, sizeof(fps), "%.0f FPS", double(s.fps));
    ImVec2 ts = body_->CalcTextSizeA(body, FLT_MAX, 0.0f, fps);
    textAt(dl, body_, body, {size.x - m - ts.x, m}, rgba(0x444444), fps);
  }
  // How the demo runs on a CPU device, top-left, under the title (the parameters sit top-right)
  if (!s.notice.empty())
    textAt(dl, body_, body, {m, m * 0.8f + title_->FontSize + 0.4f * body}, rgba(0x666666), s.notice.c_str());
}

ImVec2 Hud::drawButtons(const HudState& s, HudActions& a) {
  // Buttons for wind, reset and pins, bottom-right.
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  const float m = 20.0f * scale_;
  ImGui::SetNextWindowPos({size.x - m, size.y - m}, ImGuiCond_Always, {1.0f, 1.0f});
  ImGui::Begin("##buttons", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav);
  if (ImGui::Button(s.wind ? "Wind: on" : "Wind: off")) a.toggle_wind = true;
  ImGui::SameLine();
  if (ImGui::Button("Reset")) a.reset = true;
  ImGui::SameLine();
  if (ImGui::Button("View")) a.reset_view = true;
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the camera back to the start view (C)");
  ImGui::SameLine();
  if (ImGui::Button(s.pins ? "Pins: on" : "Pins: off")) a.toggle_pins = true;
  ImGui::SameLine();
  if (ImGui::Button(s.paused ? "Resume" : "Pause")) a.toggle_pause = true;
  ImGui::SameLine();
  bool follow = s.follow;
  if (ImGui::Checkbox("Follow", &follow)) a.toggle_follow = true;
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the camera keeps a tossed sheet in view (F)");
  const ImVec2 buttons = ImGui::GetWindowPos();
  ImGui::End();
  return buttons;
}

void Hud::drawHints(const HudState& s, const SimParams& params, ImVec2 buttons) {
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  const float m = 20.0f * scale_, body = body_->FontSize;
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  // Controls hint, bottom-left; above the buttons' row when the window is too narrow for both.
  const char* hint =
      "R to Reset \xc2\xb7 W to toggle Wind \xc2\xb7 I to toggle FPS \xc2\xb7 P to toggle Pins "
      "\xc2\xb7 Space to Pause \xc2\xb7 F to toggle Follow \xc2\xb7 Wheel or H while grabbing to crumple";
  const float hint_size = body * 0.9f;
  const ImVec2 hint_extent = body_->CalcTextSizeA(hint_size, FLT_MAX, 0.0f, hint);
  float hint_y = size.y - m - hint_size;
  if (m + hint_extent.x > buttons.x - 0.5f * m) hint_y = std::min(hint_y, buttons.y - 0.5f * m - hint_size);
  textAt(dl, body_, hint_size, {m, hint_y}, rgba(0x666666), hint);

  // Instruction line, centred at the bottom, fading out after 4 seconds ("Click and drag to
  // crumple" alone, after 3, on the crumple page).
  const bool crumple = params.release == ReleaseMode::DragVelocity;
  const double shown = crumple ? kCrumpleInstructionSeconds : kInstructionSeconds;
  double fade = 1.0 - std::clamp((s.seconds - shown) / kFadeSeconds, 0.0, 1.0);
  if (fade <= 0.0) return;
  const char* text = crumple ? "Click and drag to crumple" : "Click and drag to interact \xc2\xb7 Right-drag to orbit";
  ImVec2 ts = body_->CalcTextSizeA(body, FLT_MAX, 0.0f, text);
  // Above the buttons (and the hint) when the window is too narrow for them side by side
  float y = size.y - m * 2.6f;
  if ((size.x + ts.x) * 0.5f > buttons.x - 0.5f * m) y = std::min(y, hint_y - 0.6f * m - ts.y);
  textAt(dl, body_, body, {(size.x - ts.x) * 0.5f, y}, rgba(0x555555, float(fade)), text);
}

void Hud::drawPanel(const HudState& s, SimParams& params, HudActions& a) {
  // The parameter panel, collapsed at first, under the FPS counter: anchored to the top-right
  // corner in every frame, so a resized window keeps it there.
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  const float m = 20.0f * scale_;
  ImGui::SetNextWindowPos({size.x - m, m + body_->FontSize * 1.8f}, ImGuiCond_Always, {1.0f, 0.0f});
  ImGui::SetNextWindowCollapsed(true, ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize({320.0f * scale_, 0.0f}, ImGuiCond_FirstUseEver);
  if (ImGui::Begin("Parameters", nullptr, ImGuiWindowFlags_NoSavedSettings)) {
    if (ImGui::BeginCombo("preset", params.preset.c_str())) {
      for (auto& name : presetNames())
        if (ImGui::Selectable(name.c_str(), name == params.preset)) a.preset = name;
      ImGui::EndCombo();
    }
    // Sliders over the ranges `--set` accepts (the parameter table); wide ones are logarithmic.
    auto slideUint = [&](const char* label, const char* key, uint32_t& v) {
      const ParamInfo info = *paramInfo(key);
      int i = int(v);
      if (ImGui::SliderInt(label, &i, int(info.lo), int(info.hi), "%d", ImGuiSliderFlags_Logarithmic))
        v = uint32_t(i), a.live_changed = true;
    };
    auto slideFloat = [&](const char* label, const char* key, float& v, const char* format, bool logarithmic) {
      const ParamInfo info = *paramInfo(key);
      a.live_changed |= ImGui::SliderFloat(label, &v, float(info.lo), float(info.hi), format,
                                           logarithmic ? ImGuiSliderFlags_Logarithmic : 0);
    };
    slideUint("substeps", "substeps", params.substeps);
    slideUint("iterations", "iterations", params.iterations);
    slideFloat("damping", "damping", params.damping, "%.4f", false);
    slideFloat("wind strength", "wind_strength", params.wind_strength, "%.2f", true);
    slideFloat("tear factor", "tear_factor", params.tear_factor, "%.2f", true);
    a.live_changed |= ImGui::Checkbox("collision", &params.collision);
    int grid[2] = {int(params.cols), int(params.rows)};
    if (ImGui::InputInt2("grid (cols, rows)", grid)) {
      params.cols = uint32_t(std::clamp(grid[0], int(paramInfo("cols")->lo), int(paramInfo("cols")->hi)));
      params.rows = uint32_t(std::clamp(grid[1], int(paramInfo("rows")->lo), int(paramInfo("rows")->hi)));
    }
    if (ImGui::Button("Rebuild sheet")) a.rebuild = true;
    if (!s.device.empty()) ImGui::TextDisabled("%s", s.device.c_str());
    if (s.triangles > 0) ImGui::Text("%u triangles", s.triangles);
    if (s.times && !s.times->ms.empty() && ImGui::CollapsingHeader("GPU time per pass", ImGuiTreeNodeFlags_DefaultOpen))
      passTimes(*s.times);
  }
  ImGui::End();
}

void Hud::passTimes(const PassTimes& times) {
  // What the last tick measured: each pass, or for the fused tick the one dispatch that runs them
  // all (the passes it fuses have no time of their own)
  double total = 0.0;
  for (auto& [name, ms] : times.ms) {
    if (ms <= 0.0) continue;
    ImGui::Text("%-10s %7.3f ms", name == "fused_tick" ? "fused tick" : name.c_str(), ms);
    total += ms;
  }
  ImGui::Text("%-10s %7.3f ms", "total", total);
}

} // namespace tender::demo
