// Hinges and creases: the signed dihedral angle against closed forms and finite differences, a
// fold that stays in paper and springs back in cloth, wind that creases nothing, creases that do
// not depend on the iteration count, every value finite through a flat fold, and the stretch
// limit that keeps paper from stretching under the hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "common/sim_helpers.h"
#include "core/intersections.h"
#include "core/stats.h"
#include "cpu/cpu_solver.h"

namespace tender::test {
namespace {

using shaderio::gridHinge;
using shaderio::hingeAngle;
using shaderio::HingeAngle;

constexpr double kDeg = 180.0 / 3.14159265358979323846;

/// The hinge angle in double precision from its definition (atan2 of (nb x na) . e and na . nb |e|).
double angleOf(const glm::dvec3& u, const glm::dvec3& v, const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 e = v - u, na = glm::cross(e, a - u), nb = glm::cross(u - v, b - v);
  return std::atan2(glm::dot(glm::cross(nb, na), e), glm::dot(na, nb) * glm::length(e));
}

/// A hinge along x from (0,0,0) to (1,0,0): corner a at (0.4, 1, 0) in the plane, corner b folded
/// by `fold` radians about the edge from its flat place (0.6, -1, 0), towards +z for fold > 0.
std::array<glm::vec3, 4> foldedHinge(double fold) {
  const glm::vec3 u(0.0f), v(1.0f, 0.0f, 0.0f), a(0.4f, 1.0f, 0.0f);
  const glm::vec3 b(0.6f, float(-std::cos(fold)), float(std::sin(fold)));
  return {u, v, a, b};
}

TEST(Hinge, TheAngleIsTheSignedFoldAndAtan2IsWithinAMicroradian) {
  for (double deg = -179.0; deg <= 180.0; deg += 0.5) {
    const auto h = foldedHinge(deg / kDeg);
    const HingeAngle g = hingeAngle(h[0], h[1], h[2], h[3], true);
    ASSERT_TRUE(g.valid) << deg;
    EXPECT_NEAR(g.angle * kDeg, deg, 1e-4) << deg;
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> any(-1e3f, 1e3f);
  double worst = 0.0;
  for (int k = 0; k < 200000; ++k) {
    const float y = any(rng) * (k % 3 == 0 ? 1e-4f : 1.0f), x = any(rng);
    worst = std::max(worst, std::abs(double(shaderio::simAtan2(y, x)) - std::atan2(double(y), double(x))));
  }
  std::printf("simAtan2: largest error %.3g rad over 200000 points\n", worst);
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(shaderio::simAtan2(0.0f, 0.0f), 0.0f);
  EXPECT_FLOAT_EQ(shaderio::simAtan2(0.0f, -1.0f), 3.14159265f);
}

TEST(Hinge, TheGradientIsTheAnglesDerivative) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
  for (int trial = 0; trial < 200; ++trial) {
    auto h = foldedHinge(double(trial % 40 - 20) * 0.15);
    for (glm::vec3& p : h) p += glm::vec3(jitter(rng), jitter(rng), jitter(rng));
    const HingeAngle g = hingeAngle(h[0], h[1], h[2], h[3], true);
    ASSERT_TRUE(g.valid);
    const glm::vec3 grads[4] = {g.gu, g.gv, g.ga, g.gb};
    EXPECT_LT(glm::length(g.gu + g.gv + g.ga + g.gb), 1e-4f); // a translation turns nothing
    for (int c = 0; c < 4; ++c)
      for (int axis = 0; axis < 3; ++axis) {
        glm::dvec3 p[4] = {h[0], h[1], h[2], h[3]};
        const double step = 1e-6;
        p[c][axis] += step;
        const double up = angleOf(p[0], p[1], p[2], p[3]);
        p[c][axis] -= 2 * step;
        const double down = angleOf(p[0], p[1], p[2], p[3]);
        const double numeric = (up - down) / (2 * step);
        EXPECT_NEAR(grads[c][axis], numeric, 1e-3 * (1.0 + std::abs(numeric))) << trial << " corner " << c;
      }
  }
}

TEST(Hinge, AFlatFoldAndDegenerateTrianglesStayFinite) {
  // Folds of +-179 and 180 degrees, and through 180; a corner on the edge's line, an edge of no
  // length: every correction and multiplier finite.
  std::vector<std::array<glm::vec3, 4>> cases;
  for (double deg : {179.0, -179.0, 180.0, -180.0, 179.999, -179.999}) cases.push_back(foldedHinge(deg / kDeg));
  cases.push_back({glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(0.5f, 0, 0), glm::vec3(0.5f, -1, 0)});
  cases.push_back({glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.5f, 1, 0), glm::vec3(0.5f, -1, 0)});
  cases.push_back({glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(0.4f, 1e-20f, 0), glm::vec3(0.5f, -1, 0)});
  for (const auto& h : cases)
    for (float rest : {0.0f, 3.1415926f, -3.1415926f, 1.0f})
      for (float alpha : {0.0f, 1e-3f, 1e6f}) {
        glm::vec4 p[4];
        for (int c = 0; c < 4; ++c) p[c] = glm::vec4(h[c], 1.0f);
        float lambda = 0.0f;
        for (int it = 0; it < 16; ++it) {
          const shaderio::HingeDelta d = shaderio::solveHinge(p[0], p[1], p[2], p[3], rest, alpha, lambda);
          p[0] += glm::vec4(d.du, 0.0f);
          p[1] += glm::vec4(d.dv, 0.0f);
          p[2] += glm::vec4(d.da, 0.0f);
          p[3] += glm::vec4(d.db, 0.0f);
          lambda = d.lambda;
          ASSERT_TRUE(std::isfinite(lambda));
          for (const glm::vec4& q : p)
            for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(q[k])) << rest << " " << alpha;
        }
        const glm::vec4 st = shaderio::creaseReturn(glm::vec4(rest, 0.0f, lambda, 0.0f), 3.1415927f, 0.2f, 0.5f);
        ASSERT_TRUE(std::isfinite(st.x) && std::isfinite(st.y));
        ASSERT_LE(std::abs(st.x), 3.1415927f);
      }
}

TEST(Hinge, TheReturnMapMovesTheRestAngleByWhatPassesTheYield) {
  // |d| = 0.5 past a yield of 0.2 with hardening 0.5: the rest angle moves 0.3 / 1.5 = 0.2 and the
  // yield grows by 0.1; within the yield nothing moves; across +-pi the shorter way round.
  glm::vec4 st = shaderio::creaseReturn(glm::vec4(0.0f), 0.5f, 0.2f, 0.5f);
  EXPECT_FLOAT_EQ(st.x, 0.2f);
  EXPECT_FLOAT_EQ(st.y, 0.1f);
  EXPECT_EQ(shaderio::creaseReturn(st, 0.45f, 0.2f, 0.5f), st); // 0.25 from rest, yield 0.3
  st = shaderio::creaseReturn(glm::vec4(3.0f, 0.0f, 0.0f, 0.0f), -3.0f, 0.1f, 0.0f);
  EXPECT_NEAR(st.x, 3.0 + (2 * 3.14159265358979 - 6.0 - 0.1) - 2 * 3.14159265358979, 1e-5); // 0.183 on, past pi
  EXPECT_EQ(shaderio::creaseReturn(glm::vec4(0.0f), 1.0f, 0.0f, 0.0f), glm::vec4(0.0f));    // yield 0: elastic
}

/// A sheet of `name` laid flat on its floor (rows running back along -z), with overrides.
SimParams flatSheet(const char* name, std::vector<std::string> sets) {
  sets.insert(sets.begin(), {"tilt=90", "pins=none", "wind=off"});
  SimParams p = preset(std::string(name), sets);
  p.top_y = p.floor_y + 0.5f * p.spacing; // a top_y != 0 places the flat sheet there
  return p;
}

/// A fold in half and back at a hand's pace: the middle of the sheet's last row is carried over
/// to just above its first row (carry_s), held there pressing the fold (1 s), carried back (carry_s) and
/// let go; `rest_s` seconds follow. Returns the script and its ticks.
std::pair<std::string, int> foldScript(const SimParams& p, double rest_s, double carry_s = 1.5) {
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

/// Per interior row j of the grid, the median |angle| (degrees) of the hinges across its row edges:
/// of their geometry (`rest` false) or of their rest angles.
std::vector<double> rowMedians(const SimState& s, const SimParams& p, bool rest) {
  std::vector<double> medians(p.rows, 0.0);
  for (uint32_t j = 1; j + 1 < p.rows; ++j) {
    std::vector<double> row;
    for (uint32_t i = 0; i + 1 < p.cols; ++i) {
      const uint32_t k = (j - 1) * (p.cols - 1) + i;
      if (rest) {
        row.push_back(std::abs(double(s.hinges.at(k).x)) * kDeg);
        continue;
      }
      const glm::uvec4 q = gridHinge(k, p.cols, p.rows);
      const HingeAngle g =
          hingeAngle(glm::vec3(s.pos[q.x]), glm::vec3(s.pos[q.y]), glm::vec3(s.pos[q.z]), glm::vec3(s.pos[q.w]), false);
      row.push_back(g.valid ? std::abs(double(g.angle)) * kDeg : 0.0);
    }
    std::nth_element(row.begin(), row.begin() + row.size() / 2, row.end());
    medians[j] = row[row.size() / 2];
  }
  return medians;
}

struct FoldResult {
  double fold_line_deg = 0.0;  ///< the largest median |angle| of a row: the fold line's
  double crease_deg = 0.0;     ///< the largest median |rest angle| of a row (0 without hinges)
  double crease_sum_deg = 0.0; ///< the sum of the rows' median |rest angle|: the whole crease, however wide
  float most_stretch = 0.0f;   ///< the largest structural stretch at any tick
  uint32_t nans = 0;
};

FoldResult foldAndUnfold(const SimParams& p, double rest_s = 5.0, double carry_s = 1.5) {
  CpuSolver solver;
  Simulation sim(p, solver);
  auto [text, ticks] = foldScript(p, rest_s, carry_s);
  sim.setScript(script(text.c_str()));
  FoldResult r;
  SimState s;
  for (int t = 0; t < ticks; ++t) {
    sim.tick();
    solver.readback(s);
    const SheetStats st = computeStats(s, p.substepDt());
    r.most_stretch = std::max(r.most_stretch, st.max_stretch);
    r.nans += st.nan_count;
  }
  for (double m : rowMedians(s, p, false)) r.fold_line_deg = std::max(r.fold_line_deg, m);
  if (!s.hinges.empty())
    for (double m : rowMedians(s, p, true)) r.crease_deg = std::max(r.crease_deg, m), r.crease_sum_deg += m;
  std::printf("%s: fold line %.1f deg, crease %.1f deg (%.1f over its rows), most stretch %.4f\n", p.preset.c_str(),
              r.fold_line_deg, r.crease_deg, r.crease_sum_deg, double(r.most_stretch));
  return r;
}

TEST(Crease, AFoldLeavesACreaseInPaper) {
  TENDER_ONE_THREAD_TEST();
  // (The crease tests and the limit's scenes below name contact off: their subject is the hinges
  // and the rings; contact's own tests and the stretch test run the presets' contact.)
  const SimParams crumple = flatSheet("crumple", {"cols=20", "rows=30", "contact_factor=0"});
  const FoldResult r = foldAndUnfold(crumple);
  EXPECT_EQ(r.nans, 0u);
  EXPECT_GE(r.fold_line_deg, 20.0);
  EXPECT_GE(r.crease_deg, 20.0);
  // The stretch limit holds the edges within 1 % of rest (1.07 without it)
  EXPECT_LE(r.most_stretch, 1.03f);
  // The receipt: a fold held by its edge alone (nothing presses it) creases its hinges by some 30
  // degrees; on the floor its 15 cm halves, three times paper's elastic length (D / rho g)^(1/3) =
  // 5 cm, lie flat and open the crease to a few degrees.
  const FoldResult receipt = foldAndUnfold(flatSheet("paper", {"contact_factor=0"}));
  EXPECT_EQ(receipt.nans, 0u);
  EXPECT_GE(receipt.crease_deg, 20.0);
  EXPECT_GE(receipt.fold_line_deg, 4.0);
}

TEST(Crease, AnElasticSheetIsFlatAgain) {
  TENDER_ONE_THREAD_TEST();
  // The tender preset's skip-one bending, and its hinges without creases
  for (const char* bending : {"dihedral=off", "dihedral=on"}) {
    const SimParams p = flatSheet("tender", {"cols=16", "rows=24", bending, "crease_yield=0"});
    const FoldResult r = foldAndUnfold(p);
    EXPECT_EQ(r.nans, 0u) << bending;
    EXPECT_LT(r.fold_line_deg, 2.0) << bending;
    EXPECT_EQ(r.crease_deg, 0.0) << bending;
  }
}

TEST(Crease, CreasesDoNotDependOnTheIterationCount) {
  TENDER_ONE_THREAD_TEST();
  // The return map runs once per substep and the hinges' stiffness is a compliance, so a fold makes
  // the same crease with 4 and with 16 iterations; what differs is the structural constraints'
  // stiffness, which shapes the fold a little
  FoldResult r[2];
  for (int k = 0; k < 2; ++k)
    r[k] = foldAndUnfold(
        flatSheet("crumple", {"cols=20", "rows=30", k == 0 ? "iterations=4" : "iterations=16", "contact_factor=0"}),
        0.5, 3.0);
  EXPECT_GE(r[0].crease_deg, 15.0);
  EXPECT_NEAR(r[0].crease_sum_deg, r[1].crease_sum_deg, 0.05 * r[1].crease_sum_deg);
  EXPECT_NEAR(r[0].crease_deg, r[1].crease_deg, 6.0);
}

TEST(Crease, WindCreasesNothing) {
  TENDER_ONE_THREAD_TEST();
  // The crumple sheet hanging from its corners in ten seconds of strong wind
  CpuSolver solver;
  const SimParams p = preset("crumple", {"cols=20", "rows=30", "wind=on", "wind_strength=3", "contact_factor=0"});
  Simulation sim(p, solver);
  const SimState s = run(sim, int(10 * p.tick_hz));
  const SheetStats st = computeStats(s, p.substepDt());
  float depth = 0.0f; // how far the wind bent it out of its plane
  for (const glm::vec4& q : s.pos) depth = std::max(depth, std::abs(q.z));
  std::printf("wind: %.2f out of its plane, largest rest angle %.3f deg, %u creased\n", double(depth),
              double(st.max_crease_deg), st.creased);
  EXPECT_GT(s.hinges.size(), 0u);
  EXPECT_GT(depth, 0.3f);
  EXPECT_LE(st.max_crease_deg, 2.0f);
}

/// The radius of gyration of the particles about their centre.
double gyration(const SimState& s) {
  glm::dvec3 c(0.0);
  for (const glm::vec4& q : s.pos) c += glm::dvec3(q);
  c /= double(s.pos.size());
  double sum = 0.0;
  for (const glm::vec4& q : s.pos) sum += glm::dot(glm::dvec3(q) - c, glm::dvec3(q) - c);
  return std::sqrt(sum / double(s.pos.size()));
}

/// The 95th percentile of the hinges' |angle| (degrees).
double hingeP95(const SimState& s, const SimParams& p) {
  std::vector<double> a;
  for (uint32_t k = 0; k < s.hinges.size(); ++k) {
    const glm::uvec4 q = gridHinge(k, p.cols, p.rows);
    const HingeAngle g =
        hingeAngle(glm::vec3(s.pos[q.x]), glm::vec3(s.pos[q.y]), glm::vec3(s.pos[q.z]), glm::vec3(s.pos[q.w]), false);
    a.push_back(g.valid ? std::abs(double(g.angle)) * kDeg : 0.0);
  }
  std::nth_element(a.begin(), a.begin() + a.size() * 95 / 100, a.end());
  return a[a.size() * 95 / 100];
}

/// The hand's crumple: the middle of a sheet lying on its floor is grabbed and lifted (1 s), the
/// hand closes around it (1 s) and holds (1 s), lowers the ball to the floor (1 s) and lets go.
std::pair<std::string, int> crumpleScript(const SimParams& p, glm::vec3 middle) {
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

TEST(Hand, ACrumpledBallKeepsItsSizeAndItsFolds) {
  TENDER_ONE_THREAD_TEST();
  // Crumpled by the hand and let go on the floor, the ball springs back a little as the hand lets
  // go of its layers (the first second), then keeps its size and its folds for five seconds.
  const SimParams p = flatSheet("crumple", {"cols=20", "rows=30"});
  CpuSolver solver;
  Simulation sim(p, solver);
  const SimState flat = run(sim, 0);
  auto [text, ticks] = crumpleScript(p, glm::vec3(flat.pos[(p.rows / 2) * p.cols + p.cols / 2]));
  sim.setScript(script(text.c_str()));
  const SimState held = run(sim, ticks - 2); // the last tick the hand holds
  EXPECT_GT(sim.closure(), 0.99f);
  const SimState settled = run(sim, 2 + int(p.tick_hz));
  const SimState later = run(sim, int(5 * p.tick_hz));
  EXPECT_EQ(sim.closure(), 0.0f); // letting go opens the hand
  const double r_flat = gyration(flat), r_held = gyration(held), r0 = gyration(settled), r5 = gyration(later);
  const double p0 = hingeP95(settled, p), p5 = hingeP95(later, p);
  std::printf("hand: radius of gyration flat %.3f, in the hand %.3f, let go %.3f, 5 s later %.3f; 95th percentile "
              "hinge angle %.1f -> %.1f deg\n",
              r_flat, r_held, r0, r5, p0, p5);
  EXPECT_EQ(computeStats(later, p.substepDt()).nan_count, 0u);
  // A ball, not a sheet: the fist of a closed hand holds the sheet's area, in layers a collision
  // radius thick, at a packing of a quarter (kHandPacking): a radius of gyration of about 0.63 x the
  // flat sheet's here
  EXPECT_LT(r_held, 0.65 * r_flat);
  EXPECT_LT(r0, 0.8 * r_flat);
  EXPECT_NEAR(r5, r0, 0.03 * r0);
  EXPECT_GT(p0, 25.0); // folded through
  EXPECT_NEAR(p5, p0, 0.1 * p0);
}

/// The largest structural stretch at any tick of `script` on sheet `p` (at most `ticks` ticks).
float mostStretch(const SimParams& p, const std::string& text, int ticks) {
  CpuSolver solver;
  Simulation sim(p, solver);
  sim.setScript(script(text.c_str()));
  float most = 0.0f;
  SimState s;
  for (int t = 0; t < ticks; ++t) {
    sim.tick();
    solver.readback(s);
    const SheetStats st = computeStats(s, p.substepDt());
    EXPECT_EQ(st.nan_count, 0u);
    most = std::max(most, st.max_stretch);
  }
  return most;
}

/// A drag: a corner of the far row of a sheet lying on its floor carried 1.5 sheet lengths back
/// over the sheet, and up, in 1.5 s.
std::pair<std::string, int> dragScript(const SimParams& p) {
  const float s = p.spacing, length = float(p.rows - 1) * s;
  const glm::vec3 from(-0.5f * float(p.cols - 1) * s, p.floor_y + 0.5f * s, -length);
  const glm::vec3 to = from + glm::vec3(0.3f, 0.3f, 1.5f) * length;
  const int carry = int(1.5f * p.tick_hz);
  std::string text = "0 grab particle " + std::to_string((p.rows - 1) * p.cols) + "\n";
  for (int t = 1; t <= carry; ++t) {
    const glm::vec3 q = from + (to - from) * (float(t) / float(carry));
    char line[128];
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t, q.x, q.y, q.z);
    text += line;
  }
  return {text, carry + 1};
}

TEST(Stretch, TheHandDragsFoldsAndCrumplesPaperWithinThreePercent) {
  TENDER_ONE_THREAD_TEST();
  // At the presets' defaults, flat on their floors: a drag, a fold in half and back, and the hand's
  // crumple, each at a hand's pace; the stretch limit holds every structural edge within 1 %
  for (const char* name : {"crumple", "paper"}) {
    const SimParams p = flatSheet(name, {});
    const glm::vec3 middle(-0.5f * float(p.cols - 1) * p.spacing + float(p.cols / 2) * p.spacing,
                           p.floor_y + 0.5f * p.spacing, -float(p.rows / 2) * p.spacing);
    const auto [drag, drag_ticks] = dragScript(p);
    const auto [fold, fold_ticks] = foldScript(p, 0.5);
    const auto [crumple, crumple_ticks] = crumpleScript(p, middle);
    const float most[3] = {mostStretch(p, drag, drag_ticks), mostStretch(p, fold, fold_ticks),
                           mostStretch(p, crumple, crumple_ticks)};
    std::printf("%s: most stretch drag %.4f, fold %.4f, crumple %.4f\n", name, double(most[0]), double(most[1]),
                double(most[2]));
    for (float m : most) EXPECT_LE(m, 1.03f) << name;
  }
  // Without it (and without the contact, whose cut holds edges back) the projection's iterations
  // leave a quarter of the drag's stretch
  SimParams loose = flatSheet("crumple", {"stretch_limit=0", "contact_factor=0"});
  const auto [drag, drag_ticks] = dragScript(loose);
  const float most = mostStretch(loose, drag, drag_ticks);
  std::printf("crumple without the limit: most stretch drag %.4f\n", double(most));
  EXPECT_GT(most, 1.1f);
}

TEST(Stretch, TheSettleSweepsHoldAFoldWithContactNearerTheLimitAndApart) {
  // The settle stage (the contact_settle key): the fold in half and back of the
  // `crumple` sheet at 30 x 45 with contact on. The contact's cut alone leaves edges it held back
  // far beyond the limit (1.19); the sweeps shorten them within the cut's bounds to within the 3 %
  // of `Stretch.TheHandDragsFoldsAndCrumplesPaperWithinThreePercent` (1.013), the sheet stays apart
  // (the exact judge every 10 ticks), and the bits do not depend on the threads
  SimParams p = flatSheet("crumple", {"cols=30", "rows=45", "contact_factor=0.5"});
  const auto [text, ticks] = foldScript(p, 0.5);
  struct Run {
    float most = 0.0f;
    uint64_t pairs = 0;
    std::vector<glm::vec4> pos;
  };
  // The bits on one thread against two's, through the first fold
  const int check = ticks / 3;
  auto run = [&](uint32_t threads, uint32_t sweeps, int last) {
    CpuOptions options;
    options.threads = threads;
    options.min_chunk = 1;
    p.contact_settle = sweeps;
    CpuSolver solver(options);
    Simulation sim(p, solver);
    sim.setScript(script(text.c_str()));
    Run r;
    SimState s;
    for (int t = 0; t < last; ++t) {
      sim.tick();
      solver.readback(s);
      r.most = std::max(r.most, computeStats(s, p.substepDt()).max_stretch);
      if (t % 10 == 9) r.pairs = std::max(r.pairs, intersectingPairs(s.pos, s.triangles, s.triangle_count).pairs);
      if (t + 1 == check) r.pos = s.pos;
    }
    return r;
  };
  const Run cut = run(2, 0, ticks), settled = run(2, 16, ticks), one = run(1, 16, check);
  std::printf("fold with contact: most stretch %.4f cut alone, %.4f with 16 settle sweeps\n", double(cut.most),
              double(settled.most));
  EXPECT_EQ(cut.pairs, 0u);
  EXPECT_EQ(settled.pairs, 0u);
  EXPECT_GT(cut.most, 1.1f);
  EXPECT_LE(settled.most, 1.03f);
  ASSERT_EQ(one.pos.size(), settled.pos.size());
  EXPECT_EQ(std::memcmp(one.pos.data(), settled.pos.data(), one.pos.size() * sizeof(glm::vec4)), 0);
}

TEST(Stretch, TheRingsVisitEveryParticleOnceAfterItsParents) {
  // Wider and longer grids, roots at corners, edges and inside: ring k holds the particles k grid
  // steps from the root, each once, and a particle's parents are one ring nearer
  for (const glm::uvec2 size : {glm::uvec2(7, 5), glm::uvec2(5, 9), glm::uvec2(1, 6), glm::uvec2(6, 1)})
    for (const uint32_t root : {0u, size.x * size.y - 1u, size.x / 2u, (size.y / 2u) * size.x + size.x / 2u}) {
      const uint32_t cols = size.x, rows = size.y, rings = shaderio::limitRings(root, cols, rows);
      std::vector<int> seen(cols * rows, 0), ring(cols * rows, -1);
      ring[root] = 0;
      for (uint32_t k = 1; k <= rings; ++k)
        for (uint32_t t = 0; t < shaderio::limitSlots(cols, rows); ++t) {
          const uint32_t i = shaderio::ringParticle(root, k, t, cols, rows);
          if (i == SIM_NONE) continue;
          ASSERT_LT(i, cols * rows);
          ++seen[i];
          ring[i] = int(k);
          const int dx = std::abs(int(i % cols) - int(root % cols)), dy = std::abs(int(i / cols) - int(root / cols));
          EXPECT_EQ(dx + dy, int(k));
          const glm::uvec2 parent = shaderio::limitParents(i, root, cols);
          for (uint32_t q : {parent.x, parent.y}) {
            if (q != SIM_NONE) {
              EXPECT_EQ(ring[q], int(k) - 1) << cols << "x" << rows << " root " << root << " " << i;
            }
          }
        }
      for (uint32_t i = 0; i < cols * rows; ++i) EXPECT_EQ(seen[i], i == root ? 0 : 1) << i;
    }
  // A large sheet's rings take several dispatches, each within lavapipe's loop count; a GPU's
  // workgroup walks a 1024-wide sheet's rings in one round of its invocations each
  for (const glm::uvec2 size : {glm::uvec2(32, 48), glm::uvec2(512, 768), glm::uvec2(4096, 4096)})
    for (const uint32_t invocations : {uint32_t(SIM_WG_LIMIT), uint32_t(SIM_WG_LIMIT_GPU)}) {
      const uint32_t per = shaderio::limitRingsPerDispatch(size.x, size.y, invocations);
      const uint32_t slots_per_invocation = (shaderio::limitSlots(size.x, size.y) + invocations - 1) / invocations;
      EXPECT_LE(per * (1 + slots_per_invocation), SIM_LIMIT_LOOP_BUDGET);
      EXPECT_GE(per, 1u);
    }
  EXPECT_GT(shaderio::limitMostRings(4096, 4096), shaderio::limitRingsPerDispatch(4096, 4096, SIM_WG_LIMIT));
  EXPECT_EQ(shaderio::limitSlots(512, 768), uint32_t(SIM_WG_LIMIT_GPU));
}

TEST(Stretch, RingsFromSeveralRootsVisitEveryParticleOnceAfterItsParents) {
  // Each particle around the root nearest it (the first of equals), in the ring of its steps from
  // that root, once, after its parents towards it: the walk of limitRing (sim_elements.glsl)
  for (const glm::uvec2 size : {glm::uvec2(7, 5), glm::uvec2(5, 9), glm::uvec2(12, 3)}) {
    const uint32_t cols = size.x, rows = size.y, n = cols * rows;
    for (const glm::uvec4 roots : {glm::uvec4(0, cols - 1, SIM_NONE, 2), glm::uvec4(0, cols / 2, cols - 1, 3),
                                   glm::uvec4(0, n - 1, n / 2, 3), glm::uvec4(3, 3, SIM_NONE, 2)}) {
      const uint32_t rings = shaderio::limitLastRing(roots, cols, rows);
      std::vector<int> seen(n, 0), ring(n, -1);
      for (uint32_t j = 0; j < roots.w; ++j) ring[roots[int(j)]] = 0;
      for (uint32_t k = 1; k <= rings; ++k)
        for (uint32_t j = 0; j < roots.w; ++j)
          for (uint32_t t = 0; t < shaderio::limitSlots(cols, rows); ++t) {
            const uint32_t i = shaderio::ringParticle(roots[int(j)], k, t, cols, rows);
            if (i == SIM_NONE || shaderio::limitRootOf(i, roots, cols) != j) continue;
            ++seen[i];
            ring[i] = int(k);
            uint32_t nearest = n;
            for (uint32_t r = 0; r < roots.w; ++r)
              nearest = std::min(nearest, shaderio::gridSteps(i, roots[int(r)], cols));
            EXPECT_EQ(nearest, k) << i;
            const glm::uvec2 parent = shaderio::limitParents(i, roots[int(j)], cols);
            for (uint32_t q : {parent.x, parent.y}) {
              if (q == SIM_NONE) continue;
              EXPECT_GE(ring[q], 0) << cols << "x" << rows << " " << i << " before its parent " << q;
              EXPECT_LT(ring[q], int(k));
            }
          }
      for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(seen[i], ring[i] == 0 ? 0 : 1) << cols << "x" << rows << " " << i;
    }
  }
  // The last ring is exactly the most steps any particle lies from its nearest root, for any roots
  // (the walk above, cut there, visits every particle): a brute-force count over the grid
  std::mt19937 rng(9);
  for (int trial = 0; trial < 400; ++trial) {
    const uint32_t cols = 1 + rng() % 40, rows = 1 + rng() % 40, n = cols * rows, count = 1 + rng() % SIM_LIMIT_ROOTS;
    glm::uvec4 roots(SIM_NONE, SIM_NONE, SIM_NONE, count);
    for (uint32_t j = 0; j < count; ++j) roots[int(j)] = rng() % n;
    uint32_t most = 0;
    for (uint32_t i = 0; i < n; ++i) {
      uint32_t nearest = ~0u;
      for (uint32_t j = 0; j < count; ++j) nearest = std::min(nearest, shaderio::gridSteps(i, roots[int(j)], cols));
      most = std::max(most, nearest);
    }
    ASSERT_EQ(shaderio::limitLastRing(roots, cols, rows), most)
        << cols << "x" << rows << " roots " << roots.x << " " << roots.y << " " << roots.z << " (" << count << ")";
    EXPECT_LE(most, shaderio::limitRingsOf(roots, cols, rows));
    if (count == 1) {
      EXPECT_EQ(most, shaderio::limitRings(roots.x, cols, rows));
    }
  }
  // The bench's 32 x 48 sheet from its two top corners: 62 rings, not the 78 from each corner's farthest
  EXPECT_EQ(shaderio::limitLastRing(glm::uvec4(0, 31, SIM_NONE, 2), 32, 48), 62u);
  EXPECT_EQ(shaderio::limitRingsOf(glm::uvec4(0, 31, SIM_NONE, 2), 32, 48), 78u);
  // No uniforms' roots: the grab's, else the middle's
  EXPECT_EQ(shaderio::limitRootSet(glm::uvec4(0u), 7u, 4, 5), glm::uvec4(7u, SIM_NONE, SIM_NONE, 1u));
  EXPECT_EQ(shaderio::limitRootSet(glm::uvec4(0u), SIM_NONE, 4, 5).x, 10u);
}

TEST(Stretch, ASheetHangingFromItsPinsHoldsTheLimitAtEachPin) {
  TENDER_ONE_THREAD_TEST();
  // The bench's sheet (the crumple preset scaled to 128 x 192), hanging from its corners and from
  // three pins: the rings run from every pin, so the edges at each are held too (rings from the
  // sheet's middle left those at the pins to the projection alone: 1.54)
  for (const char* pins : {"pins=corners", "pins=top3"}) {
    const SimParams base = preset("crumple", {"contact_factor=0"});
    const float scale = float(base.cols - 1) / 127.0f;
    SimParams p = preset("crumple", {"cols=128", "rows=192", pins, "contact_factor=0"});
    p.spacing = base.spacing * scale;
    p.cell_size = base.cell_size * scale;
    const float most = mostStretch(p, "", 30);
    std::printf("%s: most stretch %.4f\n", pins, double(most));
    EXPECT_LE(most, p.stretch_limit + 1e-4f) << pins;
  }
}

TEST(Stretch, AHeldSheetYankedTearsAndALyingOneIsLeftAlone) {
  // The sheet hanging from its corners, its bottom middle yanked down at 20 sheet lengths a second:
  // the limit draws the sheet after the hand, the pins hold their corners, and the paper tears
  const SimParams p = preset("crumple", {"cols=12", "rows=16", "wind=off", "contact_factor=0"});
  const uint32_t bottom = (p.rows - 1) * p.cols + p.cols / 2;
  CpuSolver solver;
  Simulation sim(p, solver);
  const glm::vec3 from(run(sim, 0).pos[bottom]);
  const float length = float(p.rows - 1) * p.spacing;
  std::string text = "0 grab particle " + std::to_string(bottom) + "\n";
  char line[128];
  for (int t = 1; t <= 12; ++t) {
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t, from.x, from.y - length * float(t) / 3.0f, from.z);
    text += line;
  }
  sim.setScript(script(text.c_str()));
  const SimState yanked = run(sim, 13);
  std::printf("yank: %u torn\n", tornCount(yanked));
  EXPECT_GT(tornCount(yanked), 0u);
  // A sheet lying on its floor stretches no edge past the limit: the limit leaves every bit alone
  uint64_t hash[2] = {};
  for (int k = 0; k < 2; ++k) {
    const SimParams q = flatSheet(
        "crumple", {"cols=12", "rows=16", k == 0 ? "stretch_limit=0" : "stretch_limit=1.01", "contact_factor=0"});
    CpuSolver cpu;
    Simulation rest(q, cpu);
    hash[k] = computeStats(run(rest, 60), q.substepDt()).state_hash;
  }
  EXPECT_EQ(hash[0], hash[1]);
}

} // namespace
} // namespace tender::test
