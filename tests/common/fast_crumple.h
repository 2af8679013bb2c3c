#pragma once
/// The fast crumple the CPU tests run (Contact.*, Stretch.*): a 20 x 30 `crumple` sheet lying on its
/// floor, its middle snatched up as the hand closes, swung round and let go at tick 40.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/sim_helpers.h"
#include "cpu/cpu_solver.h"

namespace tender::test {

/// A sheet of the `crumple` preset lying flat on its floor, 20 x 30, with contact on (or off).
inline SimParams flatCrumple(bool contact, std::vector<std::string> sets = {}) {
  sets.insert(sets.begin(), {"cols=20", "rows=30", "tilt=90", "pins=none", "wind=off",
                             contact ? "contact_factor=0.5" : "contact_factor=0"});
  SimParams p = preset(std::string("crumple"), sets);
  p.top_y = p.floor_y + 0.5f * p.spacing;
  return p;
}

/// Where the hand of the fast crumple is at tick t (1 to 39): the middle of the flat sheet is
/// snatched up (a third of the sheet's length in a twelfth of a second) as the hand closes, then
/// swung round in circles; `pace` times as fast (the path of tick t x pace at tick t).
inline glm::vec3 fastCrumpleHand(const SimParams& p, const SimState& flat, int t, float pace = 1.0f) {
  const glm::vec3 m(flat.pos[(p.rows / 2) * p.cols + p.cols / 2]);
  const float length = float(p.rows - 1) * p.spacing, at = float(t) * pace;
  if (at <= 5.0f) return glm::vec3(m.x, m.y + length * 0.07f * at, m.z);
  const float a = 0.35f * (at - 6.0f);
  return glm::vec3(m.x + 0.14f * length * std::cos(a), m.y + length * (0.35f - 0.09f * std::sin(a)),
                   m.z + 0.14f * length * std::sin(a));
}

/// A crumple at a hand's speed (fastCrumpleHand), let go at tick 40.
inline std::string fastCrumple(const SimParams& p, const SimState& flat, float pace = 1.0f) {
  std::string text = "0 grab particle " + std::to_string((p.rows / 2) * p.cols + p.cols / 2) + "\n";
  char line[160];
  for (int t = 1; t < 40; ++t) {
    const glm::vec3 q = fastCrumpleHand(p, flat, t, pace);
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t, q.x, q.y, q.z);
    text += line;
    if (float(t) * pace <= 5.0f) {
      std::snprintf(line, sizeof(line), "%d squeeze %.6f\n", t, std::min(0.2f * float(t) * pace, 1.0f));
      text += line;
    }
  }
  return text + "40 release\n";
}

/// The flat sheet of flatCrumple before its first tick.
inline SimState flatState() {
  CpuSolver solver;
  Simulation sim(flatCrumple(true), solver);
  return run(sim, 0);
}

/// The fastest particle but the held one in the fast crumple of `p`, while the hand moves (ticks
/// up to 40), and the fastest after it lets go; `each_tick(t, state)` sees every tick's state.
struct Fastest {
  float moving = 0.0f, let_go = 0.0f;
};
template <typename F>
Fastest fastestInTheFastCrumple(const SimParams& p, const SimState& flat, int ticks, F&& each_tick) {
  const uint32_t held = (p.rows / 2) * p.cols + p.cols / 2;
  CpuSolver solver;
  Simulation sim(p, solver);
  sim.setScript(script(fastCrumple(p, flat).c_str()));
  Fastest f;
  for (int t = 1; t <= ticks; ++t) {
    const SimState s = run(sim, 1);
    each_tick(t, s);
    for (uint32_t i = 0; i < s.pos.size(); ++i) {
      const float v = glm::length(glm::vec3(s.pos[i] - s.prev[i])) / sim.lastSubstepDt();
      if (t <= 40 && i != held) f.moving = std::max(f.moving, v);
      if (t > 40) f.let_go = std::max(f.let_go, v);
    }
  }
  return f;
}

} // namespace tender::test
