#pragma once
/// The tender-demo application: window, swapchain, renderer, solver, HUD and input. demo.cpp sets
/// it up and runs the frame loop; input.cpp turns mouse, keyboard and HUD actions into events.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <memory>
#include <optional>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include "../commands.h"
#include "core/output.h"
#include "core/simulation.h"
#include "core/stats.h"
#include "gpu/gpu_solver.h"
#include "hud.h"
#include "render/paper_mesh.h"
#include "render/renderer.h"
#include "swapchain.h"
#include "window_icon.h"

namespace tender {

constexpr uint32_t kFramesInFlight = 2;
/// How much one wheel step while grabbing closes (or opens) the hand.
constexpr float kClosurePerWheelStep = 0.25f;
constexpr const char* kTitle = "Tender \xe2\x80\x94 Receipt Paper Physics";

/// Per frame in flight: command buffer, acquire semaphore, fence.
struct FrameSync {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkSemaphore acquired = VK_NULL_HANDLE;
  VkFence done = VK_NULL_HANDLE;
};

/// A mouse press waiting for ImGui's next frame to say whether it landed on the HUD.
struct MousePress {
  bool pending = false;
  bool released = false;   ///< the button came up again before the press was resolved
  double x = 0.0, y = 0.0; ///< where the cursor was at the press
};

/// Mouse and keyboard state, filled by the GLFW callbacks.
struct Input {
  bool grabbing = false, orbiting = false, panning = false;
  double x = 0.0, y = 0.0;
  MousePress presses[3]; ///< left, right, middle
  double scroll = 0.0;   ///< wheel steps waiting, as the presses do, for ImGui's next frame
  glm::vec3 plane_point{0.0f}, plane_normal{0.0f};
  std::optional<glm::vec3> pending_move;
  bool resized = false;
};

/// A key change (key >= 0) or a typed character (key < 0) waiting for ImGui's frame.
struct KeyInput {
  int key = -1, scancode = 0, action = 0, mods = 0;
  unsigned codepoint = 0;
};

/// The keyboard as ImGui is fed it. Debian's ImGui (1.86, before its input queue) reads a key's
/// state once a frame and handles a frame's characters before its shortcut keys, so on a CPU
/// device's 10 FPS a Return tapped within one frame would be lost, and Ctrl+A followed by typing
/// within one frame would select what was typed. The events wait here and are fed a frame at a
/// time as ImGui 1.87's queue trickles them: at most one change of a key a frame, and never a
/// character and a press of a key ImGui acts on in the same frame.
struct KeyQueue {
  std::deque<KeyInput> waiting;
  bool feeding = false; ///< feed() is calling ImGui, which calls onKey back: let it pass
  void feed(GLFWwindow* w);
};

class DemoApp {
public:
  DemoApp(const CommonOptions& common, const DemoOptions& options) : common_(common), options_(options) {}
  ~DemoApp();
  int run();

private:
  bool init();
  /// The steps of init(): GLFW's window and its callbacks; the Vulkan context, its surface and the
  /// swapchain; the renderer (fitted to a CPU device) and the frames' command buffers.
  bool openWindow();
  bool createContext();
  bool createRenderer();
  /// What the HUD shows this frame, besides hs.seconds and init_progress (`times` must outlive it).
  void fillHud(demo::HudState& hs, bool started, float fps, const PassTimes& times) const;
  /// After the frame loop: the summary, the recording, and the exit status.
  int finish(uint64_t frames, double seconds);
  void initImGui(float scale);
  void createSolver();
  void attachPaper();
  void recreateSwapchain();
  void drawFrame(const render::SceneView& view);
  void apply(ScriptEvent e);
  /// Closes the hand around the grab to `closure` (clamped to 0..1) as a squeeze event.
  void squeeze(float closure);
  /// Moves the grab target to where the cursor last dragged it.
  void applyPendingMove();
  void handleActions(const demo::HudActions& a);
  /// Applies the parameters `p` as set events (script events, recorded): the keys that differ, and
  /// with `rebuild` the grid's, so the sheet is rebuilt at rest; `new_receipt` (a preset switch)
  /// also prints its receipt and frames its view.
  void applyParams(const SimParams& p, bool rebuild, bool new_receipt);
  /// The camera's start view for a preset: the spec's (6, 4, 10) towards (0, 1, 0), or for a
  /// crumple sheet, which falls to the floor at y = -10, a view from further back that shows the
  /// floor and the shadow on it.
  static render::OrbitCamera startView(const SimParams& p);
  /// Whether the camera follows a tossed sheet at the start of a preset: on for crumple and for a
  /// framed sheet (the paper receipt, render::SceneView::sheet_share), which it keeps in view as it
  /// falls.
  static bool followsByDefault(const SimParams& p);
  /// The camera back at the start view (C, the View button, a preset switch).
  void resetView();
  /// Turns the camera follow on or off (F, the HUD's Follow box).
  void setFollow(bool on);
  /// A few particles spread over the sheet (a 3 x 3 grid of the topology), read from the solver.
  std::vector<glm::vec3> sheetSamples() const;
  /// The camera follow's step: watches the sheet now and then, moves the camera every frame.
  void updateFollow(float dt);
  /// Prints the camera's follow switch and target, and where the sheet's centre is in the view
  /// ([-1, 1] across, y down) at exit.
  void printCamera() const;
  /// Width over height of the window.
  float aspect() const;
  render::Ray rayAt(double x, double y) const;
  /// Starts what a press of this mouse button on the scene does (grab, orbit, pan) at (x, y).
  void beginDrag(int button, double x, double y);
  /// Ends it when the button comes up.
  void endDrag(int button);
  /// Decides the presses and wheel steps of this frame once ImGui's NewFrame has seen them: one
  /// on a HUD window belongs to the HUD alone (the flag of the previous frame can be stale: the
  /// cursor may have reached the button in the same event batch as the click).
  void resolveMouse();
  /// Applies the wheel steps not yet applied while grabbing (off the HUD) as the hand's squeeze: in
  /// resolveMouse, and before a key or the release that came after them in the same frame, so
  /// the events apply in the order they came.
  void squeezeByWheel();

  static void onMouseButton(GLFWwindow* w, int button, int action, int mods);
  static void onCursor(GLFWwindow* w, double x, double y);
  static void onScroll(GLFWwindow* w, double dx, double dy);
  static void onKey(GLFWwindow* w, int key, int scancode, int action, int mods);
  static void onChar(GLFWwindow* w, unsigned codepoint);
  static void onResize(GLFWwindow* w, int width, int height);

  CommonOptions common_;
  DemoOptions options_;
  GLFWwindow* window_ = nullptr;
  bool no_window_ = false; ///< init() could not reach the display
  std::unique_ptr<gpu::VulkanContext> ctx_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  std::unique_ptr<demo::Swapchain> swapchain_;
  std::unique_ptr<render::Renderer> renderer_;
  Backend backend_;
  std::unique_ptr<Simulation> sim_;
  std::vector<std::unique_ptr<render::HostPaperMesh>> host_meshes_;
  std::unique_ptr<demo::Hud> hud_;
  SimParams panel_params_;
  FrameSync frames_[kFramesInFlight];
  std::vector<VkSemaphore> rendered_; // per swapchain image
  VkDescriptorPool imgui_pool_ = VK_NULL_HANDLE;
  bool imgui_ready_ = false;
  uint32_t slot_ = 0;
  render::OrbitCamera camera_;
  render::CameraFollow follow_;
  bool follow_on_ = false;
  float follow_clock_ = 0.0f; ///< seconds since the follow last looked at the sheet
  Input input_;
  KeyQueue keys_;
  bool show_fps_ = false;
  std::string device_notice_; ///< the HUD's line on a CPU device (init)
  OutputSet record_;          // --record: written when the session ends
  std::string record_text_;   // the events of the session so far, as an input script
  SimState state_;
};

inline DemoApp* appOf(GLFWwindow* w) { return static_cast<DemoApp*>(glfwGetWindowUserPointer(w)); }

} // namespace tender
