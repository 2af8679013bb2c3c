#pragma once
/// The controller shared by every program: input state (grab, wind, pins, pause, reset), the
/// fixed-step accumulator, input scripts, and the per-tick uniforms handed to a Solver.
#include <array>
#include <cstdint>
#include <memory>

#include "params.h"
#include "script.h"
#include "sheet.h"
#include "solver.h"

namespace tender {

/// Wind acceleration at time t: uniform part and the part scaled by (u - 0.5) across the sheet.
struct WindSample {
  glm::vec3 uniform{0.0f};
  glm::vec3 twist{0.0f};
};
/// Wind of the given kind at time t (seconds), amplitude in units/s^2.
WindSample windAt(WindKind kind, double t, float amplitude);

/// Time constants of the hand: how fast it draws the sheet into the fist, and how fast its grip
/// takes a particle's velocity relative to the hand.
constexpr float kHandPullSeconds = 0.25f, kHandGripSeconds = 0.1f;

/// With contact on, the most a grab's target moves in a substep, as a share of the contact's
/// bound on a free particle's step (SIM_CONTACT_FRACTION x the contact radius): a faster hand
/// ticks in more substeps (Simulation::tickParams), so that the grab and the particles around it,
/// whose steps the bound caps (contactBounded), keep up with the hand instead of falling behind.
constexpr float kHandBoundShare = 0.4f;

class Simulation {
public:
  /// Builds the sheet and uploads it to the solver (params must be valid).
  Simulation(const SimParams& params, Solver& solver);

  const SimParams& params() const { return params_; }
  const SheetTopology& topology() const { return topo_; }
  Solver& solver() { return solver_; }

  /// Changes parameters that need no rebuild (damping, iterations, wind, tear factor, ...).
  void setLiveParams(const SimParams& p);
  /// Changes parameters and rebuilds the sheet (grid size, spacing, pins, constraint families).
  void rebuild(const SimParams& p);
  /// Applies `--set` assignments together (one step's `set` events, a HUD edit, Python's set):
  /// when one of the keys rebuilds the sheet (rebuildsSheet), the sheet is rebuilt at rest, else the
  /// running sheet takes the new values. Returns the error, changing nothing, when a key or value
  /// is bad or the result breaks checkRules().
  std::optional<std::string> set(const Settings& settings);

  /// Attaches a script; its events apply as ticks reach them.
  void setScript(InputScript script);
  /// Applies one input event now.
  void apply(const ScriptEvent& e);

  /// Grabs particle i at its current position.
  void grabParticle(uint32_t i);
  /// Grabs the nearest particle within grab_radius of the ray; returns false when none is near.
  bool grabRay(glm::vec3 origin, glm::vec3 dir);
  /// Moves the grab target (world units).
  void moveGrab(glm::vec3 target);
  /// Releases the grabbed particle (zero velocity or drag velocity, per params) and opens the hand.
  void release();
  /// Closes the hand around the grab to `closure` (0 open .. 1 closed; checkClosure): while the grab
  /// is held, the free particles within hand_reach of the grab target are gripped (they follow the
  /// hand) and drawn into a fist whose radius shrinks from hand_reach, open, to the sheet's ball
  /// (SimParams::handBallRadius), closed. Nothing happens without a grab; a new grab starts open.
  void squeeze(float closure);
  void setWind(bool on) { wind_ = on; }
  void setPins(bool on) { pins_ = on; }
  void setPaused(bool on) { paused_ = on; }
  /// Starts the animated reset (SIM_RESET_FRAMES frames).
  void reset();

  bool wind() const { return wind_; }
  bool pins() const { return pins_; }
  bool paused() const { return paused_; }
  bool resetting() const { return reset_frame_ > 0; }
  uint32_t grabbed() const { return grab_index_; }
  glm::vec3 grabTarget() const { return grab_to_; }
  float closure() const { return closure_; }

  /// Applies the script's events due before the next step (tick() and advance() do this first;
  /// a fleet does it for every sheet before it ticks them, so a grab's read-back comes before the
  /// batch runs).
  void applyDueEvents();
  /// One frame of headless time: the script's events for this tick, then one physics tick (or one
  /// reset frame, or nothing when paused). Returns true when the solver ran physics.
  bool tick();
  /// Real-time frame: clamps dt, runs as many fixed ticks as the accumulator holds (one reset
  /// frame while resetting), applying each script event before the step it is due at. Returns
  /// the number of physics ticks run. No step goes past step `last` (the demo's --quit-at).
  int advance(float frame_dt, uint64_t last = UINT64_MAX);

  /// Steps so far, the clock of scripts: one per physics tick, reset frame or paused frame (tick()
  /// runs one step; advance() as many as the frame's time holds).
  uint64_t frameCount() const { return frame_; }
  /// Grabs that caught a particle so far (from input or a script).
  uint32_t grabCount() const { return grabs_; }
  /// Physics ticks run so far (the wind's clock).
  uint64_t physicsTicks() const { return physics_ticks_; }
  /// Uniforms of the next physics tick (for tests and tools).
  shaderio::SimUniforms makeUniforms() const;
  /// The parameters the next physics tick runs with: the sheet's, but with contact on and a grab
  /// moving more than kHandBoundShare of the contact's bound a substep, more substeps (up to
  /// SIM_MAX_SUBSTEPS) and the damping that keeps the tick's.
  SimParams tickParams() const;
  /// Uniforms the solver ran its last tick (or reset frame) with.
  const shaderio::SimUniforms& lastUniforms() const { return last_uniforms_; }
  /// The substep of the last physics tick (its substeps may be more than the sheet's: tickParams),
  /// in seconds: a particle's velocity is (pos - prev) / this.
  float lastSubstepDt() const { return last_uniforms_.dt > 0.0f ? last_uniforms_.dt : params_.substepDt(); }

private:
  void grabAt(uint32_t i, glm::vec3 position);
  /// makeUniforms' parts: the stretch limit's, and each substep's wind and grab.
  void setLimitUniforms(const SimParams& p, shaderio::SimUniforms& u) const;
  void setSubstepInputs(const SimParams& p, shaderio::SimUniforms& u) const;
  void runPhysicsTick();
  void runResetFrame();

  SimParams params_;
  Solver& solver_;
  SheetTopology topo_;
  InputScript script_;
  size_t next_event_ = 0;
  bool wind_ = true, pins_ = true, paused_ = false;
  uint32_t grab_index_ = SIM_NONE;
  glm::vec3 grab_from_{0.0f}, grab_to_{0.0f};
  std::array<glm::vec3, 4> grab_history_{}; ///< grab target at the last ticks, for the drag velocity
  uint32_t grab_ticks_ = 0;
  float closure_ = 0.0f;              ///< the hand around the grab: 0 open .. 1 closed
  uint32_t release_index_ = SIM_NONE; ///< particle released with drag velocity at the next tick
  glm::vec3 release_velocity_{0.0f};
  uint32_t reset_frame_ = 0; ///< frames left in the animated reset
  uint64_t frame_ = 0, physics_ticks_ = 0;
  // Contact (SimUniforms::contact_check): whether the last physics tick had contact on (off: the
  // next one checks every triangle for crossing)
  bool contact_on_last_ = false;
  uint32_t grabs_ = 0;
  double accumulator_ = 0.0;
  shaderio::SimUniforms last_uniforms_{};
};

} // namespace tender
