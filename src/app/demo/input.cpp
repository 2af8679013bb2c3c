// tender-demo input: mouse grab/orbit/zoom/pan, keys, HUD actions; every input that changes the
// simulation goes through apply() as a script event, so it can be recorded and replayed.
#include <algorithm>
#include <cstdio>

#include "demo_app.h"

namespace tender {

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
  case GLFW_KEY_C:
    app.camera_ = startView(app.sim_->params());
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

render::OrbitCamera DemoApp::startView(const SimParams& p) {
  render::OrbitCamera c;
  if (p.preset.rfind("crumple", 0) == 0) c.lookAt({7.0f, 3.0f, 19.0f}, {0.0f, -1.8f, 0.0f});
  return c;
}

void DemoApp::switchParams(const SimParams& p, bool new_receipt) {
  ctx_->waitIdle();
  input_.grabbing = false;
  input_.pending_move.reset();
  if (new_receipt) {
    renderer_->setReceipt(render::rasterizeReceipt(render::receiptText(p.preset)));
    camera_ = startView(p);
  }
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
  if (a.reset_view) camera_ = startView(sim_->params());
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
} // namespace tender
