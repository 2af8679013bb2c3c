// tender-demo: the interactive window. GLFW + Vulkan swapchain, the scene renderer, the solver,
// the ImGui HUD, the frame loop, input recording and replay (input.cpp handles the input).
#include "demo_app.h"

namespace tender {
namespace {

// The newest GLFW error, for the one line that reports a failed start.
std::string g_glfw_error;
bool g_glfw_started = false;

} // namespace

bool DemoApp::init() {
  if (!openWindow() || !createContext() || !createRenderer()) return false;
  recreateSwapchain();

  float xs = 1.0f, ys = 1.0f;
  glfwGetWindowContentScale(window_, &xs, &ys);
  initImGui(options_.ui_scale > 0.0f ? options_.ui_scale : std::max(xs, 1.0f));

  createSolver();
  if (!backend_.solver) return false;
  std::string error;
  auto replay = scriptFor(options_.replay, common_.params, common_.backend, error);
  if (!replay) {
    fail(error);
    return false;
  }
  sim_->setScript(*replay);
  if (auto err = record_.addInput(options_.replay)) {
    fail(*err);
    return false;
  }
  if (auto err = record_.add(options_.record)) {
    fail(*err);
    return false;
  }
  record_text_ = "# tender input script recorded by tender-demo, preset " + common_.params.preset + "\n";
  return true;
}

bool DemoApp::openWindow() {
  glfwSetErrorCallback([](int code, const char* text) {
    g_glfw_error = text ? text : std::to_string(code);
    if (g_glfw_started) std::fprintf(stderr, "tender-demo: GLFW %d: %s\n", code, g_glfw_error.c_str());
  });
  if (!glfwInit()) {
    const std::string why = g_glfw_error.empty() ? std::string("no display?") : g_glfw_error;
    no_window_ = true;
    if (const char* launched = std::getenv(kLaunchedVariable); launched && *launched)
      std::printf("tender: cannot open a window (%s); rendering a picture instead\n", why.c_str());
    else
      fail("cannot open a window (" + why + "); try `tender render`");
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
  return true;
}

bool DemoApp::createContext() {
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
  return true;
}

bool DemoApp::createRenderer() {
  render::RendererOptions ro;
  ro.color_format = swapchain_->format();
  ro.final_layout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  ro.frames = kFramesInFlight;
  // A CPU device (lavapipe) runs the simulation's kernels far slower than the CPU backend does (a
  // hanging crumple tick: 271 ms against 4 ms) and draws every pixel on the same cores: unless
  // --backend gpu asks for it, the simulation runs on the CPU backend, and the picture is drawn
  // without MSAA and with a quarter of the shadow map's texels.
  if (ctx_->properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    if (!common_.backend_given && common_.backend == "gpu") {
      if (auto err = validate(common_.params, "cpu")) {
        fail(*err);
        return false;
      }
      common_.backend = "cpu";
    }
    ro.max_samples = 1;
    ro.shadow_size = RENDER_SHADOW_SIZE / 2;
    device_notice_ = std::string("CPU device: ") +
                     (common_.backend == "cpu" ? "simulating on the CPU" : "simulating on it (--backend gpu)") +
                     ", no MSAA, " + std::to_string(ro.shadow_size) + "\xc2\xb2 shadows";
    std::printf("tender-demo: %s is a %s\n", ctx_->info().name.c_str(), device_notice_.c_str());
  }
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
  return true;
}

void DemoApp::initImGui(float scale) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  hud_ = std::make_unique<demo::Hud>(scale);
  ImGui_ImplGlfw_InitForVulkan(window_, true); // chains to the callbacks installed above
  // The keyboard reaches ImGui through the key queue instead (KeyQueue): onKey and onChar queue it.
  glfwSetKeyCallback(window_, onKey);
  glfwSetCharCallback(window_, onChar);

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
  resetView();
  setFollow(followsByDefault(common_.params));
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
  if (!init()) {
    const char* launched = std::getenv(kLaunchedVariable);
    return no_window_ && launched && *launched ? kExitNoWindow : kExitBadInput;
  }
  using Clock = std::chrono::steady_clock;
  auto last = Clock::now();
  const auto start = last;
  std::optional<Clock::time_point> sim_start;
  uint64_t frames = 0;
  float fps = 0.0f, fps_time = 0.0f;
  uint32_t fps_frames = 0;
  const uint64_t last_step = options_.quit_at > 0 ? options_.quit_at : UINT64_MAX; // --quit-at

  // Ctrl-C, SIGTERM or SIGHUP end the session as a window close does (the recording and the summary
  // are written), then say so.
  catchInterrupts();
  while (!glfwWindowShouldClose(window_) && !interrupted()) {
    glfwPollEvents();
    keys_.feed(window_);
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

    ImGui_ImplVulkan_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    resolveMouse();
    demo::HudState hs;
    hs.init_progress = renderer_->ready() ? 1.0f : renderer_->buildNext();
    if (renderer_->ready()) {
      if (!sim_start) sim_start = now;
      applyPendingMove();
      sim_->advance(dt, last_step);
      updateFollow(dt);
      backend_.solver->computeNormals();
    }
    PassTimes times = backend_.solver->passTimes();
    hs.seconds = sim_start ? std::chrono::duration<double>(now - *sim_start).count() : 0.0;
    fillHud(hs, sim_start.has_value(), fps, times);
    demo::HudActions actions = hud_->draw(hs, panel_params_);
    render::SceneView view = render::defaultSceneView(sim_->params());
    view.camera = camera_;
    drawFrame(view);
    handleActions(actions);
    ++frames;
    if (sim_->frameCount() >= last_step) break; // --quit-at
  }
  return finish(frames, std::chrono::duration<double>(Clock::now() - start).count());
}

void DemoApp::fillHud(demo::HudState& hs, bool started, float fps, const PassTimes& times) const {
  // "Initialising…" stays for a moment, then fades out over half a second.
  hs.init_alpha = started ? float(std::clamp(1.0 - (hs.seconds - 0.4) / 0.5, 0.0, 1.0)) : 1.0f;
  hs.fps = fps;
  hs.show_fps = show_fps_;
  hs.paused = sim_->paused();
  hs.wind = sim_->wind();
  hs.pins = sim_->pins();
  hs.device = ctx_->info().name;
  hs.notice = device_notice_;
  hs.times = &times;
  hs.follow = follow_on_;
  if (input_.grabbing && sim_->grabbed() != SIM_NONE) {
    // The grab target on the screen, in window pixels
    int ww = 0, wh = 0;
    glfwGetWindowSize(window_, &ww, &wh);
    if (auto v = camera_.viewPoint(sim_->grabTarget(), aspect()))
      hs.grab_point = (*v * 0.5f + 0.5f) * glm::vec2(float(ww), float(wh));
    hs.closure = sim_->closure();
  }
}

int DemoApp::finish(uint64_t frames, double seconds) {
  ctx_->waitIdle();
  SimState state;
  backend_.solver->readback(state);
  std::printf("tender-demo: %llu frames in %.1f s (%.1f FPS), %llu physics ticks, %u grabs\n",
              static_cast<unsigned long long>(frames), seconds, seconds > 0 ? double(frames) / seconds : 0.0,
              static_cast<unsigned long long>(sim_->physicsTicks()), sim_->grabCount());
  printCamera();
  // The script clock's steps: `tender sim --script <the recording> --ticks <steps>` ends in this state
  const std::string steps = std::to_string(sim_->frameCount()), hash = hashHex(hashPositions(state.pos));
  std::printf("tender-demo: %s steps, state hash %s\n", steps.c_str(), hash.c_str());
  if (!options_.record.empty()) {
    record_text_ += "# " + steps + " steps: tender sim --script <this file> --ticks " + steps + " ends at state hash " +
                    hash + "\n";
    if (auto err = record_.stage(options_.record, record_text_)) return fail(*err);
    if (auto err = record_.commit()) return fail(*err);
  }
  if (common_.validation && ctx_->validationMessages() > 0)
    return fail(std::to_string(ctx_->validationMessages()) + " validation messages");
  if (interrupted())
    return fail(interruptMessage() +
                (options_.record.empty() ? "" : "; the session is recorded in " + options_.record));
  return 0;
}

void DemoApp::printCamera() const {
  const glm::vec3 t = camera_.target();
  char centre[64] = "behind the camera";
  if (auto v = camera_.viewPoint(render::centreOf(sheetSamples()), aspect()))
    std::snprintf(centre, sizeof centre, "at %.2f %.2f in the view", double(v->x), double(v->y));
  std::printf("tender-demo: camera follow %s, target %.2f %.2f %.2f, the sheet's centre %s\n",
              follow_on_ ? "on" : "off", double(t.x), double(t.y), double(t.z), centre);
}

const char* const kProgramName = "tender-demo";

int runDemo(const CommonOptions& common, const DemoOptions& options) {
  DemoApp app(common, options);
  return app.run();
}

} // namespace tender
