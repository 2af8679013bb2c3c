// tender-demo: the interactive window. GLFW + Vulkan swapchain, the scene renderer, the solver,
// mouse and keyboard interaction, the ImGui HUD, input recording and replay.
#include <algorithm>
#include <chrono>
#include <cstdio>
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
#include "gpu/gpu_solver.h"
#include "hud.h"
#include "render/paper_mesh.h"
#include "render/renderer.h"
#include "swapchain.h"
#include "window_icon.h"

namespace tender {
namespace {

constexpr uint32_t kFramesInFlight = 2;
constexpr const char* kTitle = "Tender \xe2\x80\x94 Receipt Paper Physics";

// Per frame in flight: command buffer, acquire semaphore, fence.
struct FrameSync {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkSemaphore acquired = VK_NULL_HANDLE;
  VkFence done = VK_NULL_HANDLE;
};

// Mouse and keyboard state, filled by the GLFW callbacks.
struct Input {
  bool grabbing = false, orbiting = false, panning = false;
  double x = 0.0, y = 0.0;
  glm::vec3 plane_point{0.0f}, plane_normal{0.0f};
  std::optional<glm::vec3> pending_move;
  bool resized = false;
};

class DemoApp {
public:
  DemoApp(const CommonOptions& common, const DemoOptions& options) : common_(common), options_(options) {}
  ~DemoApp();
  int run();

private:
  bool init();
  void initImGui(float scale);
  void createSolver();
  void attachPaper();
  void recreateSwapchain();
  void drawFrame(const render::SceneView& view);
  void apply(ScriptEvent e);
  void handleActions(const demo::HudActions& a);
  void switchParams(const SimParams& p, bool new_receipt);
  render::Ray cursorRay() const;

  static void onMouseButton(GLFWwindow* w, int button, int action, int mods);
  static void onCursor(GLFWwindow* w, double x, double y);
  static void onScroll(GLFWwindow* w, double dx, double dy);
  static void onKey(GLFWwindow* w, int key, int scancode, int action, int mods);
  static void onResize(GLFWwindow* w, int width, int height);

  CommonOptions common_;
  DemoOptions options_;
  GLFWwindow* window_ = nullptr;
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
  Input input_;
  bool show_fps_ = false;
  uint32_t grabs_ = 0;      // grabs that caught a particle
  OutputSet record_;        // --record: written when the session ends
  std::string record_text_; // the events of the session so far, as an input script
  SimState state_;
};

DemoApp* appOf(GLFWwindow* w) { return static_cast<DemoApp*>(glfwGetWindowUserPointer(w)); }

// The newest GLFW error, for the one line that reports a failed start.
std::string g_glfw_error;
bool g_glfw_started = false;

bool DemoApp::init() {
  glfwSetErrorCallback([](int code, const char* text) {
    g_glfw_error = text ? text : std::to_string(code);
    if (g_glfw_started) std::fprintf(stderr, "tender-demo: GLFW %d: %s\n", code, g_glfw_error.c_str());
  });
  if (!glfwInit()) {
    fail("cannot open a window (" + (g_glfw_error.empty() ? std::string("no display?") : g_glfw_error) +
         "); try `tender render`");
    return false;
  }
  g_glfw_started = true;
  if (!glfwVulkanSupported()) {
    fail("the Vulkan loader has no window-system support");
    return false;
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);
  window_ = glfwCreateWindow(int(options_.width), int(options_.height), kTitle, nullptr, nullptr);
  if (!window_) {
    fail("cannot create the window");
    return false;
  }
  // The icon: a paper sheet with a folded corner, at two sizes.
  std::vector<uint8_t> icon32 = demo::drawPaperIcon(32), icon64 = demo::drawPaperIcon(64);
  GLFWimage icons[2] = {{32, 32, icon32.data()}, {64, 64, icon64.data()}};
  glfwSetWindowIcon(window_, 2, icons);
  glfwSetWindowUserPointer(window_, this);
  glfwSetMouseButtonCallback(window_, onMouseButton);
  glfwSetCursorPosCallback(window_, onCursor);
  glfwSetScrollCallback(window_, onScroll);
  glfwSetKeyCallback(window_, onKey);
  glfwSetFramebufferSizeCallback(window_, onResize);

  gpu::ContextOptions co;
  co.device = common_.device;
  co.validation = common_.validation;
  co.graphics = true;
  uint32_t n = 0;
  const char** exts = glfwGetRequiredInstanceExtensions(&n);
  for (uint32_t i = 0; i < n; ++i) co.instance_extensions.push_back(exts[i]);
  co.device_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  auto created = gpu::VulkanContext::create(co);
  if (!created) {
    fail(created.error());
    return false;
  }
  ctx_ = std::move(created.value());
  VK_CHECK(glfwCreateWindowSurface(ctx_->instance(), window_, nullptr, &surface_));
  VkBool32 present = VK_FALSE;
  vkGetPhysicalDeviceSurfaceSupportKHR(ctx_->physicalDevice(), ctx_->queueFamily(), surface_, &present);
  if (!present) {
    fail("the Vulkan queue cannot present to this window");
    return false;
  }
  swapchain_ = std::make_unique<demo::Swapchain>(*ctx_, surface_, options_.vsync);

  render::RendererOptions ro;
  ro.color_format = swapchain_->format();
  ro.final_layout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  ro.frames = kFramesInFlight;
  renderer_ = std::make_unique<render::Renderer>(*ctx_, ro,
                                                 render::rasterizeReceipt(render::receiptText(common_.params.preset)));
  for (FrameSync& f : frames_) {
    VkCommandBufferAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = ctx_->commandPool();
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(ctx_->device(), &ai, &f.cmd));
    VkSemaphoreCreateInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    VK_CHECK(vkCreateSemaphore(ctx_->device(), &si, nullptr, &f.acquired));
    VkFenceCreateInfo fi{};
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    VK_CHECK(vkCreateFence(ctx_->device(), &fi, nullptr, &f.done));
  }
  recreateSwapchain();

  float xs = 1.0f, ys = 1.0f;
  glfwGetWindowContentScale(window_, &xs, &ys);
  initImGui(options_.ui_scale > 0.0f ? options_.ui_scale : std::max(xs, 1.0f));

  createSolver();
  if (!backend_.solver) return false;
  std::string error;
  auto replay = scriptFor(options_.replay, common_.params, error);
  if (!replay) {
    fail(error);
    return false;
  }
  sim_->setScript(*replay);
  if (auto err = record_.add(options_.record)) {
    fail(*err);
    return false;
  }
  record_text_ = "# tender input script recorded by tender-demo, preset " + common_.params.preset + "\n";
  return true;
}

void DemoApp::initImGui(float scale) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  hud_ = std::make_unique<demo::Hud>(scale);
  ImGui_ImplGlfw_InitForVulkan(window_, true); // chains to the callbacks installed above

  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16};
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  dp.maxSets = 16;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &size;
  VK_CHECK(vkCreateDescriptorPool(ctx_->device(), &dp, nullptr, &imgui_pool_));
  ImGui_ImplVulkan_InitInfo ii{};
  ii.Instance = ctx_->instance();
  ii.PhysicalDevice = ctx_->physicalDevice();
  ii.Device = ctx_->device();
  ii.QueueFamily = ctx_->queueFamily();
  ii.Queue = ctx_->queue();
  ii.DescriptorPool = imgui_pool_;
  ii.Subpass = 0;
  ii.MinImageCount = 2;
  ii.ImageCount = std::max(swapchain_->imageCount(), 2u);
  ii.MSAASamples = renderer_->samples();
  ii.CheckVkResultFn = [](VkResult r) { VK_CHECK(r); };
  ImGui_ImplVulkan_Init(&ii, renderer_->scenePass());
  ctx_->submitOnce([](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
  ImGui_ImplVulkan_DestroyFontUploadObjects();
  imgui_ready_ = true;
}

void DemoApp::createSolver() {
  BackendOptions bo = common_.backendOptions();
  bo.context = ctx_.get();
  if (auto err = createBackend(bo, backend_)) {
    fail(*err);
    return;
  }
  sim_ = std::make_unique<Simulation>(common_.params, *backend_.solver);
  panel_params_ = common_.params;
  attachPaper();
}

void DemoApp::attachPaper() {
  ctx_->waitIdle();
  host_meshes_.clear();
  for (uint32_t s = 0; s < kFramesInFlight; ++s) {
    if (backend_.gpu) {
      renderer_->setPaper(s, render::gpuPaperBuffers(*backend_.gpu));
    } else {
      host_meshes_.push_back(std::make_unique<render::HostPaperMesh>(*ctx_, sim_->topology()));
      renderer_->setPaper(s, host_meshes_.back()->buffers());
    }
  }
}

void DemoApp::recreateSwapchain() {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  if (w == 0 || h == 0) return;
  ctx_->waitIdle();
  if (!swapchain_->recreate({uint32_t(w), uint32_t(h)})) return;
  renderer_->setTargets(swapchain_->extent(), swapchain_->views());
  for (VkSemaphore s : rendered_) vkDestroySemaphore(ctx_->device(), s, nullptr);
  rendered_.assign(swapchain_->imageCount(), VK_NULL_HANDLE);
  for (VkSemaphore& s : rendered_) {
    VkSemaphoreCreateInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    VK_CHECK(vkCreateSemaphore(ctx_->device(), &si, nullptr, &s));
  }
  if (imgui_ready_) ImGui_ImplVulkan_SetMinImageCount(2);
  input_.resized = false;
}

DemoApp::~DemoApp() {
  // No checked calls here: the destructor also runs while a Vulkan error unwinds.
  if (ctx_) vkDeviceWaitIdle(ctx_->device());
  if (imgui_ready_) {
    ImGui_ImplVulkan_Shutdown();
    ImGui_ImplGlfw_Shutdown();
  }
  if (ImGui::GetCurrentContext()) ImGui::DestroyContext();
  if (ctx_) {
    VkDevice dev = ctx_->device();
    if (imgui_pool_) vkDestroyDescriptorPool(dev, imgui_pool_, nullptr);
    for (VkSemaphore s : rendered_) vkDestroySemaphore(dev, s, nullptr);
    for (FrameSync& f : frames_) {
      if (f.acquired) vkDestroySemaphore(dev, f.acquired, nullptr);
      if (f.done) vkDestroyFence(dev, f.done, nullptr);
      if (f.cmd) vkFreeCommandBuffers(dev, ctx_->commandPool(), 1, &f.cmd);
    }
  }
  host_meshes_.clear();
  sim_.reset();
  backend_ = Backend{};
  renderer_.reset();
  swapchain_.reset();
  if (surface_) vkDestroySurfaceKHR(ctx_->instance(), surface_, nullptr);
  ctx_.reset();
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

render::Ray DemoApp::cursorRay() const {
  int w = 0, h = 0;
  glfwGetWindowSize(window_, &w, &h);
  return camera_.ray(float(input_.x), float(input_.y), float(std::max(w, 1)), float(std::max(h, 1)));
}

void DemoApp::apply(ScriptEvent e) {
  e.tick = sim_->frameCount();
  sim_->apply(e);
  if (!options_.record.empty()) record_text_ += formatEvent(e) + "\n";
}

void DemoApp::onMouseButton(GLFWwindow* w, int button, int action, int) {
  DemoApp& app = *appOf(w);
  Input& in = app.input_;
  glfwGetCursorPos(w, &in.x, &in.y);
  const bool press = action == GLFW_PRESS;
  if (press && ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse) return;
  if (!app.renderer_->ready()) return;
  if (button == GLFW_MOUSE_BUTTON_LEFT) {
    if (press) {
      // Grab the nearest particle within the pick radius of the cursor's ray.
      render::Ray r = app.cursorRay();
      ScriptEvent e;
      e.kind = EventKind::GrabRay;
      e.a = r.origin;
      e.b = r.dir;
      app.apply(e);
      if (app.sim_->grabbed() != SIM_NONE) {
        ++app.grabs_;
        in.grabbing = true;
        in.plane_point = app.sim_->grabTarget();
        in.plane_normal = app.camera_.forward();
      }
    } else if (in.grabbing) {
      if (in.pending_move) {
        ScriptEvent m;
        m.kind = EventKind::Move;
        m.a = *in.pending_move;
        app.apply(m);
        in.pending_move.reset();
      }
      ScriptEvent e;
      e.kind = EventKind::Release;
      app.apply(e);
      in.grabbing = false;
    }
  } else if (button == GLFW_MOUSE_BUTTON_RIGHT) {
    in.orbiting = press;
  } else if (button == GLFW_MOUSE_BUTTON_MIDDLE) {
    in.panning = press;
  }
}

void DemoApp::onCursor(GLFWwindow* w, double x, double y) {
  DemoApp& app = *appOf(w);
  Input& in = app.input_;
  const float dx = float(x - in.x), dy = float(y - in.y);
  in.x = x;
  in.y = y;
  if (in.grabbing) {
    // The grabbed particle follows the cursor on the camera-facing plane through the grab point.
    if (auto p = render::intersectPlane(app.cursorRay(), in.plane_point, in.plane_normal)) in.pending_move = *p;
  }
  if (in.orbiting) app.camera_.orbit(dx, dy);
  if (in.panning) {
    int ww = 0, wh = 0;
    glfwGetWindowSize(w, &ww, &wh);
    app.camera_.pan(dx, dy, float(wh));
  }
}

void DemoApp::onScroll(GLFWwindow* w, double, double dy) {
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse) return;
  appOf(w)->camera_.zoom(float(dy));
}

void DemoApp::onKey(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureKeyboard) return;
  DemoApp& app = *appOf(w);
  if (!app.sim_) return;
  ScriptEvent e;
  e.toggle = Toggle::Flip;
  switch (key) {
  case GLFW_KEY_R:
    e.kind = EventKind::Reset;
    break;
  case GLFW_KEY_W:
    e.kind = EventKind::Wind;
    break;
  case GLFW_KEY_P:
    e.kind = EventKind::Pins;
    break;
  case GLFW_KEY_SPACE:
    e.kind = EventKind::Pause;
    break;
  case GLFW_KEY_I:
    app.show_fps_ = !app.show_fps_;
    return;
  case GLFW_KEY_ESCAPE:
    glfwSetWindowShouldClose(w, GLFW_TRUE);
    return;
  default:
    return;
  }
  if (e.kind == EventKind::Reset) app.input_.grabbing = false;
  app.apply(e);
}

void DemoApp::onResize(GLFWwindow* w, int, int) { appOf(w)->input_.resized = true; }

void DemoApp::switchParams(const SimParams& p, bool new_receipt) {
  ctx_->waitIdle();
  input_.grabbing = false;
  input_.pending_move.reset();
  if (new_receipt) renderer_->setReceipt(render::rasterizeReceipt(render::receiptText(p.preset)));
  sim_->rebuild(p);
  panel_params_ = p;
  attachPaper();
}

void DemoApp::handleActions(const demo::HudActions& a) {
  ScriptEvent e;
  e.toggle = Toggle::Flip;
  if (a.toggle_wind) e.kind = EventKind::Wind, apply(e);
  if (a.toggle_pins) e.kind = EventKind::Pins, apply(e);
  if (a.toggle_pause) e.kind = EventKind::Pause, apply(e);
  if (a.reset) e.kind = EventKind::Reset, apply(e);
  if (a.preset) {
    if (auto p = presetParams(*a.preset)) switchParams(*p, true);
  } else if (a.rebuild) {
    if (auto err = validate(panel_params_, common_.backend))
      std::fprintf(stderr, "tender-demo: %s\n", err->c_str());
    else
      switchParams(panel_params_, false);
  } else if (a.live_changed) {
    if (!validate(panel_params_, common_.backend)) {
      // Grid size edits wait for "Rebuild sheet"; everything else applies now.
      SimParams live = panel_params_;
      live.cols = sim_->params().cols;
      live.rows = sim_->params().rows;
      sim_->setLiveParams(live);
    }
  }
}

void DemoApp::drawFrame(const render::SceneView& view) {
  VkDevice dev = ctx_->device();
  FrameSync& f = frames_[slot_];
  VK_CHECK(vkWaitForFences(dev, 1, &f.done, VK_TRUE, UINT64_MAX));
  uint32_t image = 0;
  VkResult r = vkAcquireNextImageKHR(dev, swapchain_->handle(), UINT64_MAX, f.acquired, VK_NULL_HANDLE, &image);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    recreateSwapchain();
    ImGui::EndFrame();
    return;
  }
  if (r != VK_SUBOPTIMAL_KHR) VK_CHECK(r);
  VK_CHECK(vkResetFences(dev, 1, &f.done));

  // The CPU backend's state goes to this slot's host-visible buffers.
  if (!host_meshes_.empty()) {
    backend_.solver->readback(state_);
    host_meshes_[slot_]->update(state_);
  }
  ImGui::Render();

  VK_CHECK(vkResetCommandBuffer(f.cmd, 0));
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(f.cmd, &bi));
  renderer_->record(f.cmd, slot_, image, view,
                    [](VkCommandBuffer cmd) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd); });
  VK_CHECK(vkEndCommandBuffer(f.cmd));

  VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &f.acquired;
  si.pWaitDstStageMask = &wait_stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &f.cmd;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &rendered_[image];
  VK_CHECK(vkQueueSubmit(ctx_->queue(), 1, &si, f.done));
  VkPresentInfoKHR pi{};
  pi.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR;
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &rendered_[image];
  VkSwapchainKHR sc = swapchain_->handle();
  pi.swapchainCount = 1;
  pi.pSwapchains = &sc;
  pi.pImageIndices = &image;
  r = vkQueuePresentKHR(ctx_->queue(), &pi);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR || input_.resized)
    recreateSwapchain();
  else
    VK_CHECK(r);
  slot_ = (slot_ + 1) % kFramesInFlight;
}

int DemoApp::run() {
  if (!init()) return kExitBadInput;
  using Clock = std::chrono::steady_clock;
  auto last = Clock::now();
  const auto start = last;
  std::optional<Clock::time_point> sim_start;
  uint64_t frames = 0;
  float fps = 0.0f, fps_time = 0.0f;
  uint32_t fps_frames = 0;
  std::string device = ctx_->info().name;

  while (!glfwWindowShouldClose(window_)) {
    glfwPollEvents();
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    if (w == 0 || h == 0) { // minimised: nothing to draw, the simulation waits
      glfwWaitEventsTimeout(0.1);
      last = Clock::now();
      continue;
    }
    if (input_.resized) recreateSwapchain();
    auto now = Clock::now();
    float dt = std::chrono::duration<float>(now - last).count();
    last = now;
    fps_time += dt;
    ++fps_frames;
    if (fps_time >= 0.5f) {
      fps = float(fps_frames) / fps_time;
      fps_time = 0.0f;
      fps_frames = 0;
    }

    demo::HudState hs;
    hs.init_progress = renderer_->ready() ? 1.0f : renderer_->buildNext();
    if (renderer_->ready()) {
      if (!sim_start) sim_start = now;
      if (input_.pending_move) {
        ScriptEvent m;
        m.kind = EventKind::Move;
        m.a = *input_.pending_move;
        apply(m);
        input_.pending_move.reset();
      }
      sim_->advance(dt);
      backend_.solver->computeNormals();
    }
    hs.seconds = sim_start ? std::chrono::duration<double>(now - *sim_start).count() : 0.0;
    // "Initialising…" stays for a moment, then fades out over half a second.
    hs.init_alpha = sim_start ? float(std::clamp(1.0 - (hs.seconds - 0.4) / 0.5, 0.0, 1.0)) : 1.0f;
    hs.fps = fps;
    hs.show_fps = show_fps_;
    hs.paused = sim_->paused();
    hs.wind = sim_->wind();
    hs.pins = sim_->pins();
    hs.device = device;
    PassTimes times = backend_.solver->passTimes();
    hs.times = &times;

    ImGui_ImplVulkan_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    demo::HudActions actions = hud_->draw(hs, panel_params_);
    render::SceneView view = render::defaultSceneView(sim_->params());
    view.camera = camera_;
    drawFrame(view);
    handleActions(actions);
    ++frames;
  }
  ctx_->waitIdle();
  double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("tender-demo: %llu frames in %.1f s (%.1f FPS), %llu physics ticks, %u grabs\n",
              static_cast<unsigned long long>(frames), seconds, seconds > 0 ? double(frames) / seconds : 0.0,
              static_cast<unsigned long long>(sim_->physicsTicks()), grabs_);
  if (!options_.record.empty()) {
    if (auto err = record_.stage(options_.record, record_text_)) return fail(*err);
    if (auto err = record_.commit()) return fail(*err);
  }
  if (common_.validation && ctx_->validationMessages() > 0)
    return fail(std::to_string(ctx_->validationMessages()) + " validation messages");
  return 0;
}

} // namespace

int runDemo(const CommonOptions& common, const DemoOptions& options) {
  DemoApp app(common, options);
  return app.run();
}

} // namespace tender
