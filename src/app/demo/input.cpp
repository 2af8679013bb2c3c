// tender-demo input: mouse grab/orbit/zoom/pan, keys, HUD actions; every input that changes the
// simulation goes through apply() as a script event, or applyParams() as set events (the HUD's
// parameter edits), so it can be recorded and replayed.
#include <algorithm>
#include <cstdio>

#include "demo_app.h"

namespace tender {

render::Ray DemoApp::rayAt(double x, double y) const {
  int w = 0, h = 0;
  glfwGetWindowSize(window_, &w, &h);
  return camera_.ray(float(x), float(y), float(std::max(w, 1)), float(std::max(h, 1)));
}

void DemoApp::apply(ScriptEvent e) {
  e.tick = sim_->frameCount();
  sim_->apply(e);
  if (!options_.record.empty()) record_text_ += formatEvent(e) + "\n";
}

void DemoApp::squeeze(float closure) {
  ScriptEvent e;
  e.kind = EventKind::Squeeze;
  e.closure = std::clamp(closure, 0.0f, 1.0f);
  if (e.closure != sim_->closure()) apply(e);
}

void DemoApp::applyPendingMove() {
  if (!input_.pending_move) return;
  ScriptEvent m;
  m.kind = EventKind::Move;
  m.a = *input_.pending_move;
  apply(m);
  input_.pending_move.reset();
}

void DemoApp::onMouseButton(GLFWwindow* w, int button, int action, int) {
  DemoApp& app = *appOf(w);
  if (button < 0 || button >= int(std::size(app.input_.presses))) return;
  MousePress& p = app.input_.presses[button];
  if (action == GLFW_PRESS) {
    // Decided in resolveMouse(), after ImGui has seen the press
    p = {true, false, 0.0, 0.0};
    glfwGetCursorPos(w, &p.x, &p.y);
  } else if (p.pending) {
    p.released = true;
  } else {
    app.endDrag(button);
  }
}

void DemoApp::squeezeByWheel() {
  // The wheel while grabbing closes the hand (away from you) or opens it, a quarter per step.
  if (input_.scroll == 0.0 || !input_.grabbing || ImGui::GetIO().WantCaptureMouse) return;
  squeeze(sim_->closure() + kClosurePerWheelStep * float(input_.scroll));
  input_.scroll = 0.0;
}

void DemoApp::resolveMouse() {
  const bool on_hud = ImGui::GetIO().WantCaptureMouse;
  squeezeByWheel();
  if (!on_hud && input_.scroll != 0.0 && !input_.grabbing) {
    camera_.zoom(float(input_.scroll));
    follow_.stop();
  }
  input_.scroll = 0.0;
  for (int b = 0; b < int(std::size(input_.presses)); ++b) {
    const MousePress p = input_.presses[b];
    input_.presses[b] = {};
    if (!p.pending || on_hud || !renderer_->ready()) continue;
    beginDrag(b, p.x, p.y);
    if (p.released) endDrag(b);
  }
}

void DemoApp::beginDrag(int button, double x, double y) {
  Input& in = input_;
  if (button == GLFW_MOUSE_BUTTON_LEFT) {
    // Grab the nearest particle within the pick radius of the cursor's ray.
    render::Ray r = rayAt(x, y);
    ScriptEvent e;
    e.kind = EventKind::GrabRay;
    e.a = r.origin;
    e.b = r.dir;
    apply(e);
    if (sim_->grabbed() != SIM_NONE) {
      in.grabbing = true;
      in.plane_point = sim_->grabTarget();
      in.plane_normal = camera_.forward();
    }
  } else if (button == GLFW_MOUSE_BUTTON_RIGHT) {
    in.orbiting = true;
  } else if (button == GLFW_MOUSE_BUTTON_MIDDLE) {
    in.panning = true;
  }
}

void DemoApp::endDrag(int button) {
  Input& in = input_;
  if (button == GLFW_MOUSE_BUTTON_LEFT && in.grabbing) {
    squeezeByWheel(); // wheel steps of this frame came before the release
    applyPendingMove();
    ScriptEvent e;
    e.kind = EventKind::Release;
    apply(e);
    in.grabbing = false;
  } else if (button == GLFW_MOUSE_BUTTON_RIGHT) {
    in.orbiting = false;
  } else if (button == GLFW_MOUSE_BUTTON_MIDDLE) {
    in.panning = false;
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
    if (auto p = render::intersectPlane(app.rayAt(x, y), in.plane_point, in.plane_normal)) in.pending_move = *p;
  }
  if (in.orbiting || in.panning) app.follow_.stop();
  if (in.orbiting) app.camera_.orbit(dx, dy);
  if (in.panning) {
    int ww = 0, wh = 0;
    glfwGetWindowSize(w, &ww, &wh);
    app.camera_.pan(dx, dy, float(wh));
  }
}

void DemoApp::onScroll(GLFWwindow* w, double, double dy) { appOf(w)->input_.scroll += dy; }

void KeyQueue::feed(GLFWwindow* w) {
  // ImGui acts on a key press only when the key is one of its own (Enter, Backspace, the arrows,
  // A for Ctrl+A, ...); characters and the presses of other keys may share a frame.
  const ImGuiIO& io = ImGui::GetIO();
  auto imguiKey = [&](int key) {
    return std::find(std::begin(io.KeyMap), std::end(io.KeyMap), key) != std::end(io.KeyMap);
  };
  std::vector<int> changed;
  bool typed = false, pressed = false; // a character; a press of one of ImGui's keys
  feeding = true;
  for (; !waiting.empty(); waiting.pop_front()) {
    const KeyInput& e = waiting.front();
    if (e.key < 0) {
      if (pressed) break;
      ImGui_ImplGlfw_CharCallback(w, e.codepoint);
      typed = true;
      continue;
    }
    bool own_press = e.action != GLFW_RELEASE && imguiKey(e.key);
    if ((typed && own_press) || std::find(changed.begin(), changed.end(), e.key) != changed.end()) break;
    ImGui_ImplGlfw_KeyCallback(w, e.key, e.scancode, e.action, e.mods);
    changed.push_back(e.key);
    pressed = pressed || own_press;
  }
  feeding = false;
}

void DemoApp::onChar(GLFWwindow* w, unsigned codepoint) {
  KeyInput e;
  e.codepoint = codepoint;
  appOf(w)->keys_.waiting.push_back(e);
}

void DemoApp::onKey(GLFWwindow* w, int key, int scancode, int action, int mods) {
  DemoApp& app = *appOf(w);
  if (app.keys_.feeding) return;
  // (ImGui 1.86 repeats a held key itself and ignores GLFW's repeats: queued, they would only wait.)
  if (app.imgui_ready_ && action != GLFW_REPEAT) app.keys_.waiting.push_back({key, scancode, action, mods, 0});
  if (action != GLFW_PRESS) return;
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureKeyboard) return;
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
  case GLFW_KEY_H:
    // The hand around the grab: closed into a ball, or open again
    if (!app.input_.grabbing) return;
    app.squeezeByWheel(); // wheel steps of this frame came before the key
    app.squeeze(app.sim_->closure() < 1.0f ? 1.0f : 0.0f);
    return;
  case GLFW_KEY_I:
    app.show_fps_ = !app.show_fps_;
    return;
  case GLFW_KEY_C:
    app.resetView();
    return;
  case GLFW_KEY_F:
    app.setFollow(!app.follow_on_);
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

namespace {

// How often the camera follow reads the sheet's sample points (a few small read-backs each).
constexpr float kFollowSampleSeconds = 0.1f;

bool isCrumple(const SimParams& p) { return p.preset.rfind("crumple", 0) == 0; }

} // namespace

render::OrbitCamera DemoApp::startView(const SimParams& p) {
  render::OrbitCamera c = render::defaultSceneView(p).camera;
  if (isCrumple(p)) c.lookAt({7.0f, 3.0f, 19.0f}, {0.0f, -1.8f, 0.0f});
  return c;
}

bool DemoApp::followsByDefault(const SimParams& p) {
  return isCrumple(p) || render::defaultSceneView(p).sheet_share > 0.0f;
}

void DemoApp::resetView() {
  camera_ = startView(sim_->params());
  follow_.stop();
}

void DemoApp::setFollow(bool on) {
  follow_on_ = on;
  follow_.stop();
  if (on) follow_.arm();                // turned on: go and find the sheet wherever it is
  follow_clock_ = kFollowSampleSeconds; // look at the sheet on the next frame
}

std::vector<glm::vec3> DemoApp::sheetSamples() const {
  return backend_.solver->particlePositions(tender::sheetSamples(sim_->topology()));
}

void DemoApp::updateFollow(float dt) {
  // The user's hand is on the sheet or the camera: they decide what is in view
  if (!follow_on_ || input_.grabbing || input_.orbiting || input_.panning) return;
  follow_clock_ += dt;
  if (follow_clock_ >= kFollowSampleSeconds) {
    follow_clock_ = 0.0f;
    follow_.watch(sheetSamples(), camera_, aspect());
  }
  follow_.update(camera_, dt);
}

float DemoApp::aspect() const {
  int w = 0, h = 0;
  glfwGetWindowSize(window_, &w, &h);
  return float(std::max(w, 1)) / float(std::max(h, 1));
}

void DemoApp::applyParams(const SimParams& p, bool rebuild, bool new_receipt) {
  // The keys that differ from the sheet's (the solver's stay as they are), and with `rebuild` the
  // grid's, which rebuild the sheet at rest: one step's set events, applied together and recorded.
  Settings settings;
  if (p.preset != sim_->params().preset) settings.emplace_back("preset", p.preset);
  const auto now = paramValues(sim_->params()), next = paramValues(p);
  for (size_t k = 0; k < next.size(); ++k) {
    const std::string& key = next[k].first;
    if (paramInfo(key)->scope == ParamScope::Solver) continue;
    if (next[k].second != now[k].second || (rebuild && (key == "cols" || key == "rows"))) settings.push_back(next[k]);
  }
  if (settings.empty()) return;
  const bool rebuilds = rebuildsSheet(settings);
  if (rebuilds) {
    ctx_->waitIdle();
    input_.grabbing = false;
    input_.pending_move.reset();
  }
  const uint64_t tick = sim_->frameCount();
  if (auto err = sim_->set(settings)) {
    std::fprintf(stderr, "tender-demo: %s\n", err->c_str());
    return;
  }
  if (!options_.record.empty())
    for (const auto& [key, value] : settings) {
      ScriptEvent e;
      e.tick = tick;
      e.kind = EventKind::Set;
      e.key = key;
      e.value = value;
      record_text_ += formatEvent(e) + "\n";
    }
  if (!rebuilds) return;
  if (new_receipt) {
    renderer_->setReceipt(render::rasterizeReceipt(render::receiptText(p.preset)));
    resetView();
    setFollow(followsByDefault(p));
  }
  panel_params_ = sim_->params();
  attachPaper();
}

void DemoApp::handleActions(const demo::HudActions& a) {
  ScriptEvent e;
  e.toggle = Toggle::Flip;
  if (a.toggle_wind) e.kind = EventKind::Wind, apply(e);
  if (a.toggle_pins) e.kind = EventKind::Pins, apply(e);
  if (a.toggle_pause) e.kind = EventKind::Pause, apply(e);
  if (a.reset) e.kind = EventKind::Reset, apply(e);
  if (a.reset_view) resetView();
  if (a.toggle_follow) setFollow(!follow_on_);
  // Parameter edits are set events, recorded like every other input.
  if (a.preset) {
    if (auto p = presetParams(*a.preset)) applyParams(*p, true, true);
  } else if (a.rebuild) {
    if (auto err = validate(panel_params_, common_.backend))
      std::fprintf(stderr, "tender-demo: %s\n", err->c_str());
    else
      applyParams(panel_params_, true, false);
  } else if (a.live_changed) {
    if (!validate(panel_params_, common_.backend)) {
      // Grid size edits wait for "Rebuild sheet"; everything else applies now.
      SimParams live = panel_params_;
      live.cols = sim_->params().cols;
      live.rows = sim_->params().rows;
      applyParams(live, false, false);
    }
  }
}
} // namespace tender
