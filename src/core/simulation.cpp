#include "simulation.h"

#include <algorithm>

#include <cmath>

namespace tender {
namespace {

constexpr double kTwoPi = 6.283185307179586;

// Smooth 1-D value noise in [-1, 1]: hashed values at integer knots, smoothstep between them.
double valueNoise(double x, uint32_t seed) {
  auto knot = [seed](int64_t i) {
    uint32_t h = uint32_t(i) * 747796405u + seed * 2891336453u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    h = (h >> 22u) ^ h;
    return double(h) / 2147483647.5 - 1.0;
  };
  double f = std::floor(x);
  double t = x - f, s = t * t * (3.0 - 2.0 * t);
  return knot(int64_t(f)) * (1.0 - s) + knot(int64_t(f) + 1) * s;
}

// A grab target within the coordinates an input may name (kMaxCoordinate): a far drag or a huge
// script value moves the sheet far, never to infinity.
glm::vec3 boundedTarget(glm::vec3 p) {
  for (int k = 0; k < 3; ++k) p[k] = std::isnan(p[k]) ? 0.0f : glm::clamp(p[k], -kMaxCoordinate, kMaxCoordinate);
  return p;
}

double fractalNoise(double t, uint32_t seed) {
  return 0.65 * valueNoise(t * 0.6, seed) + 0.35 * valueNoise(t * 1.7, seed + 101u);
}

} // namespace

WindSample windAt(WindKind kind, double t, float amplitude) {
  WindSample w;
  double a = amplitude;
  if (kind == WindKind::Sinusoid) {
    // 1.3 Hz + 2.7 Hz in X, 0.7 Hz in Y, 1.1 Hz + 3.1 Hz in Z, over a steady breeze towards +Z.
    double x = 0.6 * std::sin(kTwoPi * 1.3 * t) + 0.3 * std::sin(kTwoPi * 2.7 * t + 1.0);
    double y = 0.2 * std::sin(kTwoPi * 0.7 * t);
    double z = 0.5 + 0.6 * std::sin(kTwoPi * 1.1 * t + 0.5) + 0.25 * std::sin(kTwoPi * 3.1 * t + 2.0);
    double twist = 0.5 * std::sin(kTwoPi * 0.9 * t + 0.3);
    w.uniform = glm::vec3(float(a * x), float(a * y), float(a * z));
    w.twist = glm::vec3(0.0f, 0.0f, float(a * twist));
  } else {
    // Smooth noise gusts in every direction, stronger across the sheet (Z).
    w.uniform = glm::vec3(float(a * 0.8 * fractalNoise(t, 1u)), float(a * 0.3 * fractalNoise(t, 2u)),
                          float(a * (0.3 + 1.0 * fractalNoise(t, 3u))));
    w.twist = glm::vec3(0.0f, 0.0f, float(a * 0.8 * fractalNoise(t, 4u)));
  }
  return w;
}

Simulation::Simulation(const SimParams& params, Solver& solver) : params_(params), solver_(solver) { rebuild(params); }

void Simulation::setLiveParams(const SimParams& p) {
  bool wind_changed = p.wind != params_.wind;
  params_ = p;
  if (wind_changed) wind_ = p.wind;
}

void Simulation::rebuild(const SimParams& p) {
  params_ = p;
  topo_ = buildSheet(params_);
  solver_.upload(topo_);
  wind_ = params_.wind;
  pins_ = params_.pins != PinMode::None;
  grab_index_ = release_index_ = SIM_NONE;
  contact_on_last_ = false;
  reset_frame_ = 0;
  physics_ticks_ = 0;
  accumulator_ = 0.0;
}

std::optional<std::string> Simulation::set(const Settings& settings) {
  SimParams p = params_;
  if (auto err = applySettings(p, settings)) return err;
  if (rebuildsSheet(settings))
    rebuild(p);
  else
    setLiveParams(p);
  return std::nullopt;
}

void Simulation::setScript(InputScript script) {
  script_ = std::move(script);
  next_event_ = 0;
  while (next_event_ < script_.events.size() && script_.events[next_event_].tick < frame_) ++next_event_;
}

void Simulation::apply(const ScriptEvent& e) {
  auto flip = [](Toggle t, bool cur) { return t == Toggle::Flip ? !cur : t == Toggle::On; };
  switch (e.kind) {
  case EventKind::GrabParticle:
    if (e.particle < topo_.particleCount()) grabParticle(e.particle);
    break;
  case EventKind::GrabRay:
    grabRay(e.a, e.b);
    break;
  case EventKind::Move:
    moveGrab(e.a);
    break;
  case EventKind::Release:
    release();
    break;
  case EventKind::Squeeze:
    squeeze(e.closure);
    break;
  case EventKind::Wind:
    wind_ = flip(e.toggle, wind_);
    break;
  case EventKind::Pins:
    pins_ = flip(e.toggle, pins_);
    break;
  case EventKind::Pause:
    paused_ = flip(e.toggle, paused_);
    break;
  case EventKind::Reset:
    reset();
    break;
  case EventKind::Set:
    set({{e.key, e.value}}); // a script's bad settings were refused when it was checked
    break;
  }
}

void Simulation::grabParticle(uint32_t i) {
  grabAt(i, solver_.particlePosition(i));
  ++grabs_;
}

void Simulation::grabAt(uint32_t i, glm::vec3 p) {
  grab_index_ = i;
  grab_from_ = grab_to_ = p;
  grab_history_.fill(p);
  grab_ticks_ = 0;
  release_index_ = SIM_NONE;
  closure_ = 0.0f;
}

bool Simulation::grabRay(glm::vec3 origin, glm::vec3 dir) {
  if (!(glm::dot(dir, dir) > 0.0f)) return false;
  dir = glm::normalize(dir);
  shaderio::PickResult r = solver_.pick(origin, dir, params_.grab_radius);
  if (r.index == SIM_NONE) return false;
  grabAt(r.index, glm::vec3(r.pos));
  ++grabs_;
  // The particle follows the cursor: it moves onto the ray at its nearest point.
  grab_to_ = boundedTarget(origin + dir * r.t);
  return true;
}

void Simulation::moveGrab(glm::vec3 target) {
  if (grab_index_ != SIM_NONE) grab_to_ = boundedTarget(target);
}

void Simulation::release() {
  if (grab_index_ == SIM_NONE) return;
  if (params_.release == ReleaseMode::DragVelocity) {
    // Average drag velocity over the last few ticks (the cursor moves less often than ticks run).
    uint32_t n = std::min<uint32_t>(grab_ticks_, uint32_t(grab_history_.size()) - 1);
    glm::vec3 oldest = grab_history_[(grab_ticks_ - n) % grab_history_.size()];
    release_velocity_ = n > 0 ? (grab_to_ - oldest) / (float(n) * params_.tickDt()) : glm::vec3(0.0f);
    release_index_ = grab_index_;
  }
  grab_index_ = SIM_NONE;
  closure_ = 0.0f;
}

void Simulation::squeeze(float closure) {
  if (grab_index_ != SIM_NONE) closure_ = std::clamp(closure, 0.0f, 1.0f);
}

void Simulation::reset() {
  grab_index_ = release_index_ = SIM_NONE;
  contact_on_last_ = false;
  closure_ = 0.0f;
  pins_ = params_.pins != PinMode::None; // the start: pinned as the preset is
  solver_.beginReset();
  reset_frame_ = SIM_RESET_FRAMES;
}

SimParams Simulation::tickParams() const {
  SimParams p = params_;
  const float bound = SIM_CONTACT_FRACTION * p.contactRadius();
  if (!(bound > 0.0f) || grab_index_ == SIM_NONE || reset_frame_ > 0) return p;
  const double most = double(kHandBoundShare) * bound, reach = glm::length(grab_to_ - grab_from_);
  const uint32_t needed = uint32_t(std::min(std::ceil(reach / most), double(SIM_MAX_SUBSTEPS)));
  if (needed <= p.substeps) return p;
  // The damping is a factor a substep: the tick's whole stays the sheet's
  p.damping = float(std::pow(double(p.damping), double(p.substeps) / double(needed)));
  p.substeps = needed;
  return p;
}

shaderio::SimUniforms Simulation::makeUniforms() const {
  const SimParams p = tickParams();
  shaderio::SimUniforms u{};
  u.particle_count = topo_.particleCount();
  u.cols = topo_.cols;
  u.rows = topo_.rows;
  u.substeps = p.substeps;
  u.constraint_count = topo_.constraintCount();
  u.triangle_count = topo_.triangleCount();
  u.hash_mask = topo_.hash_size - 1;
  u.color_count = topo_.colorCount();
  u.dt = p.substepDt();
  u.damping = p.damping;
  // The first substep takes the velocity the last tick's substeps left over to this tick's (the
  // substeps key changed between them, or the hand's pace asks for more: tickParams)
  const float last_dt = last_uniforms_.dt;
  const bool rescaled = last_dt > 0.0f && last_dt != u.dt;
  u.verlet = {rescaled ? float(double(p.damping) * double(u.dt) / double(last_dt)) : p.damping,
              rescaled ? float(double(u.dt) / double(last_dt)) : 0.0f, 0.0f, 0.0f};
  u.gravity = p.gravity;
  u.floor_y = p.floor_y;
  u.restitution = p.restitution;
  u.friction = p.friction;
  u.collision_radius = p.collisionRadius();
  u.inv_cell = 1.0f / p.cell_size;
  u.collision_stiffness = p.collision_stiffness;
  u.tear_factor = p.tear_factor;
  u.tear_kinds = (p.tear_structural ? 1u << SIM_KIND_STRUCTURAL : 0u) | (p.tear_shear ? 1u << SIM_KIND_SHEAR : 0u) |
                 (p.tear_bend ? (1u << SIM_KIND_BEND) | (1u << SIM_KIND_TRIBEND) : 0u);
  u.flags = (p.collision ? SIM_FLAG_COLLISION : 0u) | (pins_ ? SIM_FLAG_PINS : 0u) | (p.air ? SIM_FLAG_AIR : 0u);
  if (p.air) u.air = {p.airPressureFactor(), p.airFrictionFactor(), 1.0f / (3.0f * u.dt), 0.0f};
  u.stiffness = glm::vec4(p.stiffness, p.stiffness, p.bend_stiffness, p.bend_stiffness);
  u.hinge = {topo_.hinge_first, topo_.hingeCount(), 0u, 0u};
  u.crease = {p.hingeCompliance(), float(double(p.crease_yield) * (3.14159265358979323846 / 180.0)), p.crease_hardening,
              0.0f};
  u.reset_active = reset_frame_ > 0 ? 1u : 0u;
  u.reset_alpha = reset_frame_ > 0 ? float(SIM_RESET_FRAMES - reset_frame_ + 1) / float(SIM_RESET_FRAMES) : 0.0f;
  u.iterations = p.iterations;
  if (p.contactRadius() > 0.0f) {
    const float thickness = p.contactRadius() * SIM_CONTACT_THICKNESS;
    u.contact = {p.contactRadius(), SIM_CONTACT_FRACTION, thickness, SIM_CONTACT_FIXED / thickness};
  }

  u.grab_index = grab_index_ != SIM_NONE ? grab_index_ : release_index_;
  setLimitUniforms(p, u);
  if (grab_index_ != SIM_NONE && closure_ > 0.0f && p.hand_reach > 0.0f) {
    const double dt = double(u.dt);
    const float ball = std::min(p.handBallRadius(), p.hand_reach);
    u.hand = {p.hand_reach - (p.hand_reach - ball) * closure_, p.hand_reach, float(-std::expm1(-dt / kHandPullSeconds)),
              float(-std::expm1(-dt / kHandGripSeconds))};
    u.hand_motion = {(grab_to_ - grab_from_) / float(p.substeps), p.floor_y + u.hand.fist};
  }
  setSubstepInputs(p, u);
  // Every triangle is checked for crossing the sheet in the first substep of a tick when contact
  // starts (a new sheet, a reset, the key turned on) and once every SIM_CONTACT_AUDIT_TICKS ticks;
  // otherwise those already crossing (crossingChecked in contact.h)
  const bool audit = !contact_on_last_ || physics_ticks_ % SIM_CONTACT_AUDIT_TICKS == 0;
  // The settle's sweeps, with the stretch limit on
  if (u.contact.radius > 0.0f)
    u.contact_check = {audit ? SIM_CONTACT_CHECK_ALL : 0u, u.limit.reach > 0.0f ? p.contact_settle : 0u, 0u, 0u};
  return u;
}

// The stretch limit (with contact, its places are steps the contact cuts as any): its reach, its
// roots (the grab, else the pins that hold the sheet: limitRootSet) and its last ring
void Simulation::setLimitUniforms(const SimParams& p, shaderio::SimUniforms& u) const {
  if (!(p.stretch_limit > 0.0f)) return;
  u.limit = {p.stretch_limit * p.spacing, p.spacing, 0.0f, 0.0f};
  const std::vector<uint32_t> pins = pins_ ? pinIndices(p.pins, p.cols, p.rows) : std::vector<uint32_t>{};
  if (grab_index_ == SIM_NONE && release_index_ == SIM_NONE && !pins.empty()) {
    u.limit_roots = glm::uvec4(SIM_NONE, SIM_NONE, SIM_NONE, 0u);
    for (const uint32_t pin : pins)
      if (u.limit_roots.w < SIM_LIMIT_ROOTS) u.limit_roots[int(u.limit_roots.w++)] = pin;
  }
  if (u.limit.reach > 0.0f) {
    const glm::uvec4 roots = shaderio::limitRootSet(u.limit_roots, u.grab_index, u.cols, u.rows);
    u.limit.last_ring = float(shaderio::limitLastRing(roots, u.cols, u.rows));
  }
}

// Each substep's wind, and where the grab's target is and was (a toss in the first substep after a
// release)
void Simulation::setSubstepInputs(const SimParams& p, shaderio::SimUniforms& u) const {
  const double t0 = double(physics_ticks_) / double(p.tick_hz);
  const double dts = 1.0 / (double(p.tick_hz) * p.substeps);
  const float amp = wind_ ? p.wind_strength * p.wind_scale : 0.0f;
  for (uint32_t s = 0; s < p.substeps; ++s) {
    WindSample w = amp > 0.0f ? windAt(p.wind_kind, t0 + double(s + 1) * dts, amp) : WindSample{};
    u.wind[s] = glm::vec4(w.uniform, 0.0f);
    u.wind_twist[s] = glm::vec4(w.twist, 0.0f);
    if (grab_index_ != SIM_NONE) {
      // The target moves from where it was at the last tick to the newest cursor position.
      float f1 = float(s + 1) / float(p.substeps), f0 = float(s) / float(p.substeps);
      glm::vec3 target = glm::mix(grab_from_, grab_to_, f1);
      glm::vec3 prev = p.release == ReleaseMode::DragVelocity ? glm::mix(grab_from_, grab_to_, f0) : target;
      u.grab_target[s] = glm::vec4(target, 1.0f);
      u.grab_prev[s] = glm::vec4(prev, 1.0f);
    } else if (release_index_ != SIM_NONE && s == 0) {
      // A toss: the first substep after release gives the particle the drag velocity and lets go.
      glm::vec3 prev = grab_to_ - release_velocity_ * float(dts);
      u.grab_target[s] = glm::vec4(grab_to_, 2.0f);
      u.grab_prev[s] = glm::vec4(prev, 1.0f);
    }
  }
}

void Simulation::runPhysicsTick() {
  last_uniforms_ = makeUniforms();
  solver_.tick(last_uniforms_);
  ++physics_ticks_;
  contact_on_last_ = last_uniforms_.contact.radius > 0.0f;
  release_index_ = SIM_NONE;
  if (grab_index_ != SIM_NONE) {
    grab_from_ = grab_to_;
    ++grab_ticks_;
    grab_history_[grab_ticks_ % grab_history_.size()] = grab_to_;
  }
}

void Simulation::runResetFrame() {
  last_uniforms_ = makeUniforms();
  solver_.tick(last_uniforms_);
  --reset_frame_;
}

void Simulation::applyDueEvents() {
  const auto& events = script_.events;
  while (next_event_ < events.size() && events[next_event_].tick <= frame_) {
    const ScriptEvent& e = events[next_event_];
    if (e.kind != EventKind::Set) {
      apply(e);
      ++next_event_;
      continue;
    }
    // The set events of one tick in a row apply together, as checkScript checked them.
    Settings settings;
    next_event_ = takeSettings(events, next_event_, settings);
    set(settings);
  }
}

bool Simulation::tick() {
  applyDueEvents();
  ++frame_;
  if (reset_frame_ > 0) {
    runResetFrame();
    return false;
  }
  if (paused_) return false;
  runPhysicsTick();
  return true;
}

int Simulation::advance(float frame_dt, uint64_t last) {
  if (frame_ >= last) return 0;
  applyDueEvents();
  if (reset_frame_ > 0) {
    ++frame_;
    runResetFrame();
    accumulator_ = 0.0;
    return 0;
  }
  if (paused_) {
    ++frame_;
    return 0;
  }
  accumulator_ += std::min(double(frame_dt), double(params_.max_frame_dt));
  int n = 0;
  const double step = 1.0 / double(params_.tick_hz);
  // Each physics tick is a step of the scripts' clock: events due before it apply first, so a
  // recording replays the same whatever the frame rate (tick() runs one step at a time).
  while (accumulator_ >= step && frame_ < last) {
    if (n > 0) {
      applyDueEvents();
      if (paused_ || reset_frame_ > 0) break;
    }
    ++frame_;
    runPhysicsTick();
    accumulator_ -= step;
    ++n;
  }
  return n;
}

} // namespace tender
