#pragma once
/// Scenes the CPU tests build in code: a sheet laid flat on its floor, a fold in half and back at a
/// hand's pace, and a crumple by a dozen grabs towards the middle.
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "common/sim_helpers.h"

namespace tender::test {

/// Degrees a radian.
inline constexpr double kDeg = 180.0 / 3.14159265358979323846;

/// Sheet `base` laid flat on its floor (rows running back along -z), with overrides.
inline SimParams flatSheet(const SimParams& base, std::vector<std::string> sets) {
  sets.insert(sets.begin(), {"tilt=90", "pins=none", "wind=off"});
  SimParams p = withSets(base, sets);
  p.top_y = p.floor_y + 0.5f * p.spacing; // a top_y != 0 places the flat sheet there
  return p;
}

/// A sheet of preset `name` laid flat on its floor, with overrides.
inline SimParams flatSheet(const char* name, std::vector<std::string> sets) {
  return flatSheet(*presetParams(name), std::move(sets));
}

/// A fold in half and back at a hand's pace: the middle of the sheet's last row is carried over
/// to just above its first row (carry_s), held there pressing the fold (1 s), carried back (carry_s) and
/// let go; `rest_s` seconds follow. Returns the script and its ticks.
inline std::pair<std::string, int> foldScript(const SimParams& p, double rest_s, double carry_s = 1.5) {
  const float s = p.spacing, length = float(p.rows - 1) * s;
  const float x = -0.5f * float(p.cols - 1) * s + float(p.cols / 2) * s;
  const float floor = p.floor_y + 0.5f * s;
  const glm::vec3 start(x, floor, -length), over(x, floor + 1.5f * s, -0.5f * s);
  const int carry = int(carry_s * p.tick_hz), hold = int(p.tick_hz);
  std::string text = "0 grab particle " + std::to_string((p.rows - 1) * p.cols + p.cols / 2) + "\n";
  auto path = [&](int t0, glm::vec3 from, glm::vec3 to) {
    for (int t = 1; t <= carry; ++t) {
      const float f = float(t) / float(carry);
      glm::vec3 q = from + (to - from) * f;
      q.y += 0.4f * length * std::sin(3.14159265f * f); // over an arc
      char line[128];
      std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t0 + t, q.x, q.y, q.z);
      text += line;
    }
  };
  path(0, start, over);
  const int back = carry + hold;
  path(back, over, start);
  text += std::to_string(back + carry + 1) + " release\n";
  return {text, back + carry + 1 + int(rest_s * p.tick_hz)};
}

/// The hand's crumple: the middle of a sheet lying on its floor is grabbed and lifted (1 s), the
/// hand closes around it (1 s) and holds (1 s), lowers the ball to the floor (1 s) and lets go.
inline std::pair<std::string, int> crumpleScript(const SimParams& p, glm::vec3 middle) {
  const int second = int(p.tick_hz);
  const float lift = 0.3f * float(p.rows - 1) * p.spacing;
  std::string text = "0 grab particle " + std::to_string((p.rows / 2) * p.cols + p.cols / 2) + "\n";
  char line[128];
  for (int t = 1; t <= second; ++t) {
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t, middle.x,
                  middle.y + lift * float(t) / float(second), middle.z);
    text += line;
  }
  for (int t = 1; t <= second; ++t) {
    std::snprintf(line, sizeof(line), "%d squeeze %.6f\n", second + t, float(t) / float(second));
    text += line;
  }
  for (int t = 1; t <= second; ++t) {
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", 3 * second + t, middle.x,
                  middle.y + lift * (1.0f - float(t) / float(second)), middle.z);
    text += line;
  }
  text += std::to_string(4 * second + 1) + " release\n";
  return {text, 4 * second + 1};
}

} // namespace tender::test
