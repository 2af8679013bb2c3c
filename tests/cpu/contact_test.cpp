// Penetration-free self-contact (shaders/shared/contact.h, cpu/cpu_contact.h): the distances it
// is built on against closed forms and brute force, the bounded step, and scripted scenes judged
// from outside by the exact triangle-triangle intersection count (core/intersections.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common/sim_helpers.h"
#include "core/intersections.h"
#include "core/stats.h"
#include "cpu/cpu_contact.h"
#include "cpu/cpu_solver.h"
#include "cpu/worker_pool.h"
#include "cpu_runs.h"
#include "shaderio.h"

namespace tender::test {
namespace {

using glm::vec3;
using shaderio::ContactPair;

/// The vector between the nearest points a ContactPair names.
vec3 separation(const ContactPair& c, vec3 x0, vec3 x1, vec3 x2, vec3 x3) {
  return x0 * c.w.x + x1 * c.w.y + x2 * c.w.z + x3 * c.w.w;
}

TEST(ContactDistance, ClosedForms) {
  const vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Over the inside: the height; beyond a corner: to the corner; beyond an edge: to the edge
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(0.25f, 0.25f, 0.5f), a, b, c).d2, 0.25f);
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(2, 0, 0), a, b, c).d2, 1.0f);
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(0.5f, -1, 1), a, b, c).d2, 2.0f);
  // Skew segments crossing 0.5 apart; parallel ones side by side; collinear ones with a gap
  EXPECT_FLOAT_EQ(shaderio::segmentSegment(vec3(-1, 0, 0), vec3(1, 0, 0), vec3(0, -1, 0.5f), vec3(0, 1, 0.5f)).d2,
                  0.25f);
  EXPECT_FLOAT_EQ(shaderio::segmentSegment(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0.5f, 0.3f, 0), vec3(2, 0.3f, 0)).d2,
                  0.09f);
  EXPECT_FLOAT_EQ(shaderio::segmentSegment(vec3(0, 0, 0), vec3(1, 0, 0), vec3(1.5f, 0, 0), vec3(3, 0, 0)).d2, 0.25f);
  // Zero-length segments and triangles of no area are points and segments
  EXPECT_FLOAT_EQ(shaderio::segmentSegment(vec3(0, 0, 0), vec3(0, 0, 0), vec3(0, 2, 0), vec3(0, 2, 0)).d2, 4.0f);
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(0.5f, 1, 0), a, b, vec3(2, 0, 0)).d2, 1.0f);
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(0, 3, 0), a, a, a).d2, 9.0f);
}

TEST(ContactDistance, NeverAboveTheNearestSampledPointsAndTheWeightsNameThem) {
  // Random triangles and segments, thin and degenerate ones among them: the distance is at most
  // the nearest of a fine sampling of the primitives (it is a minimum), at least that less the
  // sampling's spacing, and the weights give a vector of that length.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto point = [&] { return vec3(u(rng), u(rng), u(rng)); };
  constexpr int kSteps = 64;
  for (int trial = 0; trial < 400; ++trial) {
    vec3 a = point(), b = point(), c = point(), p = point();
    if (trial % 10 == 0) c = a + (b - a) * 0.3f; // no area
    const ContactPair vf = shaderio::pointTriangle(p, a, b, c);
    float sampled = 1e30f, longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; i + j <= kSteps; ++j) {
        const vec3 q = a + (b - a) * (float(i) / kSteps) + (c - a) * (float(j) / kSteps);
        sampled = std::min(sampled, glm::dot(p - q, p - q));
      }
    ASSERT_TRUE(std::isfinite(vf.d2));
    EXPECT_LE(vf.d2, sampled * 1.0001f + 1e-9f) << trial;
    EXPECT_GE(std::sqrt(vf.d2), std::sqrt(sampled) - 2.0f * longest / kSteps) << trial;
    EXPECT_NEAR(glm::length(separation(vf, p, a, b, c)), std::sqrt(vf.d2), 1e-4f) << trial;

    vec3 q0 = point(), q1 = point();
    if (trial % 10 == 1) q1 = q0 + (b - a) * 0.5f; // parallel
    const ContactPair ee = shaderio::segmentSegment(a, b, q0, q1);
    sampled = 1e30f;
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; j <= kSteps; ++j) {
        const vec3 d = (a + (b - a) * (float(i) / kSteps)) - (q0 + (q1 - q0) * (float(j) / kSteps));
        sampled = std::min(sampled, glm::dot(d, d));
      }
    longest = std::max(glm::length(b - a), glm::length(q1 - q0));
    ASSERT_TRUE(std::isfinite(ee.d2));
    EXPECT_LE(ee.d2, sampled * 1.0001f + 1e-9f) << trial;
    EXPECT_GE(std::sqrt(ee.d2), std::sqrt(sampled) - 2.0f * longest / kSteps) << trial;
    EXPECT_NEAR(glm::length(separation(ee, a, b, q0, q1)), std::sqrt(ee.d2), 1e-4f) << trial;
  }
}

TEST(ContactDistance, ABoundedStepGoesNoFartherThanItsBound) {
  const vec3 x0(1.0f, 2.0f, 3.0f);
  EXPECT_EQ(shaderio::boundedStep(x0, x0 + vec3(0.1f, 0, 0), 0.2f), x0 + vec3(0.1f, 0, 0)); // within: unchanged
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  for (int k = 0; k < 1000; ++k) {
    const vec3 x(u(rng), u(rng), u(rng));
    const float bound = 0.01f * float(k % 100);
    const vec3 y = shaderio::boundedStep(x0, x, bound);
    EXPECT_LE(glm::length(y - x0), bound * 1.000001f + 1e-6f);
    if (bound == 0.0f) {
      EXPECT_EQ(y, x0);
      continue;
    }
    // Along the step it was to make, not back
    EXPECT_LE(glm::length(glm::cross(y - x0, x - x0)), 1e-4f * glm::length(y - x0) * glm::length(x - x0));
    EXPECT_GT(glm::dot(y - x0, x - x0), 0.0f);
  }
  // The bound is the fraction of the distance less the margin; within the margin, nothing: a pair
  // pressed together stops, and its push, at most a tenth of the distance less half the margin, parts it
  EXPECT_NEAR(shaderio::stepBound(0.25f, 1.0f, 0.4f), 0.4f * (0.5f - SIM_CONTACT_MARGIN), 1e-7f);
  EXPECT_EQ(shaderio::stepBound(1e-8f, 1.0f, 0.4f), 0.0f);
  // The push: a tenth of the distance less half the margin (1e-3 - 5e-5 for a radius of 0.1)
  const vec3 cut = shaderio::contactPushWithin(vec3(0.0f, 3.0f, 4.0f), 1e-6f, 0.1f);
  EXPECT_NEAR(glm::length(cut), 9.5e-5f, 1e-9f);
  EXPECT_NEAR(cut.z / cut.y, 4.0f / 3.0f, 1e-5f);
  EXPECT_EQ(shaderio::contactPushWithin(vec3(1e-5f, 0.0f, 0.0f), 1e-6f, 0.1f), vec3(1e-5f, 0.0f, 0.0f));
  EXPECT_EQ(shaderio::contactPushWithin(vec3(1e-5f, 0.0f, 0.0f), 1e-12f, 0.1f), vec3(0.0f)); // within m/2
  // A pair whose two sides each move their whole bound and push towards the other, substep after
  // substep (the push is the mean of a particle's pairs, so it may point at another primitive than
  // the one it parts the particle from): it never ends closer than the least of its start and half
  // the margin. A push of a tenth of the distance alone let it close by a fifth each substep.
  const float m = SIM_CONTACT_MARGIN;
  for (const float start : {3.0f * m, m, 0.7f * m, 0.5f * m, 0.3f * m}) {
    float d = start, old = start;
    for (int substep = 0; substep < 200; ++substep) {
      const vec3 push = shaderio::contactPushWithin(vec3(1.0f, 0.0f, 0.0f), d * d, 1.0f);
      d -= 2.0f * (shaderio::stepBound(d * d, 1.0f, SIM_CONTACT_FRACTION) + glm::length(push));
      ASSERT_GE(d, 0.999f * std::min(start, 0.5f * m)) << start << " after " << substep;
      old -= 2.0f * (shaderio::stepBound(old * old, 1.0f, SIM_CONTACT_FRACTION) + SIM_CONTACT_PUSH_FRACTION * old);
    }
    EXPECT_LT(old, 1e-2f * m) << start;
  }
}

TEST(ContactDistance, APairWithinTheMarginMayPartAndSlideButNotClose) {
  // A particle a third of the margin above a triangle in the plane z = 0 (contact radius 1): it may
  // not go down at all, it may go up and along as far as its ball, and it is not held where it is
  // (within the margin the bound was once zero in every direction: a particle pressed there stayed
  // until its push, a tenth of its distance less half the margin, parted it)
  const float radius = 1.0f, m = SIM_CONTACT_MARGIN * radius, f = SIM_CONTACT_FRACTION;
  const vec3 p(0.25f, 0.25f, m / 3.0f), a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const ContactPair pair = shaderio::pointTriangle(p, a, b, c);
  ASSERT_LT(pair.d2, m * m);
  EXPECT_EQ(shaderio::slideBound(pair.d2, radius, f), shaderio::stepBound(radius * radius, radius, f));
  const shaderio::SlideHalf up = shaderio::slideConstraint(p, a, b, c, pair, false, radius, f, 0);
  EXPECT_EQ(up.h.w, 0.0f);
  EXPECT_NEAR(up.h.z, 1.0f, 1e-6f);
  const vec3 away(0.0f, 0.0f, 0.1f), towards(0.0f, 0.0f, -0.1f), along_up(0.1f, 0.0f, 0.01f);
  EXPECT_EQ(shaderio::slideShare(up, away), 1.0f);
  EXPECT_EQ(shaderio::slideExcess(up, away), vec3(0.0f));
  EXPECT_EQ(shaderio::slideShare(up, along_up), 1.0f);
  EXPECT_EQ(shaderio::slideShare(up, towards), 0.0f);
  // The triangle's corners likewise: away from the particle, not towards it
  const shaderio::SlideHalf down = shaderio::slideConstraint(p, a, b, c, pair, false, radius, f, 1);
  EXPECT_EQ(down.h.w, 0.0f);
  EXPECT_EQ(shaderio::slideShare(down, towards), 1.0f);
  EXPECT_EQ(shaderio::slideShare(down, away), 0.0f);
  // Two primitives that touch have no normal: nothing moves
  const ContactPair touching = shaderio::pointTriangle(vec3(0.25f, 0.25f, 0.0f), a, b, c);
  EXPECT_EQ(shaderio::slideBound(touching.d2, radius, f), 0.0f);
  EXPECT_LT(shaderio::slideConstraint(vec3(0.25f, 0.25f, 0.0f), a, b, c, touching, false, radius, f, 0).h.w, 0.0f);
}

/// A sheet of the `crumple` preset lying flat on its floor, 20 x 30, with contact on (or off).
SimParams flatCrumple(bool contact, std::vector<std::string> sets = {}) {
  sets.insert(sets.begin(), {"cols=20", "rows=30", "tilt=90", "pins=none", "wind=off",
                             contact ? "contact_factor=0.5" : "contact_factor=0"});
  SimParams p = preset(std::string("crumple"), sets);
  p.top_y = p.floor_y + 0.5f * p.spacing;
  return p;
}

/// The most intersecting pairs of triangles seen every `every` ticks of `ticks` ticks of `text`
/// (and in `torn`, when given, the constraints torn at the end).
uint64_t mostPairs(const SimParams& p, const std::string& text, int ticks, int every, uint32_t threads = 2,
                   uint32_t* torn = nullptr) {
  CpuOptions o;
  o.threads = threads;
  CpuSolver solver(o);
  Simulation sim(p, solver);
  sim.setScript(script(text.c_str()));
  uint64_t most = 0;
  for (int t = 0; t < ticks; t += every) {
    const SimState s = run(sim, every);
    most = std::max(most, intersectingPairs(s.pos, s.triangles, s.triangle_count).pairs);
    if (torn) *torn = tornCount(s);
  }
  return most;
}

/// Where the hand of the fast crumple is at tick t (1 to 39): the middle of the flat sheet is
/// snatched up (a third of the sheet's length in a twelfth of a second) as the hand closes, then
/// swung round in circles; `pace` times as fast (the path of tick t x pace at tick t).
vec3 fastCrumpleHand(const SimParams& p, const SimState& flat, int t, float pace = 1.0f) {
  const vec3 m(flat.pos[(p.rows / 2) * p.cols + p.cols / 2]);
  const float length = float(p.rows - 1) * p.spacing, at = float(t) * pace;
  if (at <= 5.0f) return vec3(m.x, m.y + length * 0.07f * at, m.z);
  const float a = 0.35f * (at - 6.0f);
  return vec3(m.x + 0.14f * length * std::cos(a), m.y + length * (0.35f - 0.09f * std::sin(a)),
              m.z + 0.14f * length * std::sin(a));
}

/// A crumple at a hand's speed (fastCrumpleHand), let go at tick 40.
std::string fastCrumple(const SimParams& p, const SimState& flat, float pace = 1.0f) {
  std::string text = "0 grab particle " + std::to_string((p.rows / 2) * p.cols + p.cols / 2) + "\n";
  char line[160];
  for (int t = 1; t < 40; ++t) {
    const vec3 q = fastCrumpleHand(p, flat, t, pace);
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
SimState flatState() {
  CpuSolver solver;
  Simulation sim(flatCrumple(true), solver);
  return run(sim, 0);
}

/// Expects the script `text` to pass the flat sheet through itself with the particle repulsion
/// alone (the scene is a real test) and never with contact, judged every 5 ticks. Returns the
/// constraints torn at the end with contact.
uint32_t expectContactHolds(const char* scene, const std::string& text, int ticks,
                            const std::vector<std::string>& sets = {}) {
  uint32_t torn = 0;
  const uint64_t without = mostPairs(flatCrumple(false, sets), text, ticks, 5);
  const uint64_t with = mostPairs(flatCrumple(true, sets), text, ticks, 5, 2, &torn);
  std::printf("%s: %llu intersecting pairs at most without contact, %llu with (%u torn)\n", scene,
              (unsigned long long)without, (unsigned long long)with, torn);
  EXPECT_GT(without, 0u) << scene;
  EXPECT_EQ(with, 0u) << scene;
  return torn;
}

TEST(Contact, AFastCrumpleNeverPassesTheSheetThroughItself) {
  expectContactHolds("fast crumple", fastCrumple(flatCrumple(true), flatState()), 80);
}

TEST(Contact, NoHandIsFastEnoughToPassTheSheetThroughItself) {
  // The fast crumple with the hand twice as fast (73 units/s, the crumple sheet's length 34 times a
  // second), judged every tick: the grab is bounded like every particle (contactBounded), so it
  // falls behind such a hand instead of carrying its triangles through the layers it meets
  const SimParams p = flatCrumple(true);
  const std::string text = fastCrumple(p, flatState(), 2.0f);
  const uint64_t with = mostPairs(p, text, 60, 1);
  std::printf("fast crumple at twice the pace: %llu intersecting pairs at most\n", (unsigned long long)with);
  EXPECT_EQ(with, 0u);
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
      const float v = glm::length(vec3(s.pos[i] - s.prev[i])) / sim.lastSubstepDt();
      if (t <= 40 && i != held) f.moving = std::max(f.moving, v);
      if (t > 40) f.let_go = std::max(f.let_go, v);
    }
  }
  return f;
}

TEST(Contact, AFastCrumpleLeftOnTheFloorStaysApartAndComesToRest) {
  // The fast crumple, then four seconds on the floor: layers the constraints press together stop
  // at the contact's margin (stepBound) instead of closing in until the rounding of the positions
  // passes one through the other, and a pressed particle does not keep its speed. Contact adds no
  // speed: while the hand lifts the sheet its corners whip faster than the hand, as fast at most as
  // in the same crumple without contact at the most substeps the hand's pace can ask for
  // (Simulation::tickParams), and once it lets go nothing moves faster than the hand did (the
  // particle repulsion alone flings particles at 25-29 units/s after it)
  const SimParams p = flatCrumple(true);
  const SimState flat = flatState();
  float hand = 0.0f;
  for (int t = 1; t < 40; ++t)
    hand = std::max(
        hand, glm::length(fastCrumpleHand(p, flat, t) - (t == 1 ? vec3(flat.pos[(p.rows / 2) * p.cols + p.cols / 2])
                                                                : fastCrumpleHand(p, flat, t - 1))) *
                  p.tick_hz);
  uint64_t most = 0;
  SimState s;
  const Fastest with = fastestInTheFastCrumple(p, flat, 320, [&](int t, const SimState& at) {
    if (t % 20 == 0) most = std::max(most, intersectingPairs(at.pos, at.triangles, at.triangle_count).pairs);
    s = at;
  });
  const Fastest without = fastestInTheFastCrumple(flatCrumple(false, {"substeps=" + std::to_string(SIM_MAX_SUBSTEPS)}),
                                                  flat, 120, [](int, const SimState&) {});
  const float speed = computeStats(s, p.substepDt()).max_speed;
  std::printf("fast crumple left to lie: %llu intersecting pairs at most, %u torn, %.3f units/s at the end; fastest "
              "particle while the hand moves %.2f (without contact %.2f), after %.2f (without %.2f; the hand %.2f)\n",
              (unsigned long long)most, tornCount(s), double(speed), double(with.moving), double(without.moving),
              double(with.let_go), double(without.let_go), double(hand));
  EXPECT_EQ(most, 0u);
  EXPECT_LE(with.moving, without.moving);
  EXPECT_LE(with.let_go, hand);
  EXPECT_LT(speed, 0.5f);
}

TEST(Limit, AFastCrumpleLetGoComesToRestWithinTheLimit) {
  // Without contact: the fast crumple, then eight seconds on the floor. With nothing holding the
  // sheet, the stretch limit first shortens the over-long edges from both ends (the shorten stage),
  // then runs its rings: the ball comes to rest, every edge within the limit. (The rings alone,
  // rooted at the free middle, kept it moving at 1.8 to 3.5 units/s at 0.7 to 1.3 times this pace.)
  const SimParams p = flatCrumple(false);
  ASSERT_FLOAT_EQ(p.stretch_limit, 1.01f);
  float stretch = 0.0f;
  SimState s;
  fastestInTheFastCrumple(p, flatState(), 40 + 480, [&](int, const SimState& at) {
    stretch = std::max(stretch, computeStats(at, p.substepDt()).max_stretch);
    s = at;
  });
  const float speed = computeStats(s, p.substepDt()).max_speed;
  std::printf("fast crumple without contact, 8 s after: %.3f units/s at most, stretch %.4f at most, %u torn\n",
              double(speed), double(stretch), tornCount(s));
  EXPECT_LT(speed, 0.5f);
  EXPECT_LE(stretch, 1.0101f);
}

/// The demo's toss on a 20 x 30 `crumple` sheet lying on its floor: its middle carried off 0.32
/// units a tick for 60 ticks, then let go; 30 ticks more. The most stretch, the most substeps of a
/// tick and the most intersecting pairs (every 10 ticks).
struct Toss {
  float stretch = 0.0f;
  uint32_t substeps = 0;
  uint64_t pairs = 0;
};
Toss toss(const char* contact_factor) {
  const SimParams p = preset("crumple", {"cols=20", "rows=30", "tilt=90", "pins=none", "wind=off", "floor_y=-3",
                                         "top_y=-2.925", "tear_factor=0", "stretch_limit=0", contact_factor});
  CpuSolver solver;
  Simulation sim(p, solver);
  const uint32_t middle = (p.rows / 2) * p.cols + p.cols / 2;
  const vec3 start(run(sim, 0).pos[middle]);
  std::string text = "0 grab particle " + std::to_string(middle) + "\n";
  char line[96];
  for (int i = 1; i <= 60; ++i) {
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", i, start.x - 0.3f * float(i),
                  start.y + 0.1f * float(i), start.z);
    text += line;
  }
  sim.setScript(script((text + "61 release\n").c_str()));
  Toss r;
  for (int t = 1; t <= 90; ++t) {
    const SimState s = run(sim, 1);
    r.substeps = std::max(r.substeps, sim.lastUniforms().substeps);
    r.stretch = std::max(r.stretch, computeStats(s, sim.lastSubstepDt()).max_stretch);
    if (t % 10 == 0) r.pairs = std::max(r.pairs, intersectingPairs(s.pos, s.triangles, s.triangle_count).pairs);
  }
  return r;
}

TEST(Contact, AHandFasterThanTheBoundDragsTheSheetWithoutStretchingIt) {
  // The grab moves 0.040 a substep of 8, above the bound's 0.030 on a free particle: the hand's
  // pace asks for more substeps (Simulation::tickParams), so the sheet keeps up with the grab and
  // stretches no more than it does without contact (with 8 substeps its edges reached 41x their
  // rest length and 76 pairs of triangles crossed)
  const Toss with = toss("contact_factor=0.5"), without = toss("contact_factor=0");
  std::printf("toss with contact: %u substeps at most, stretch %.3f at most (%.3f without contact), %llu "
              "intersecting pairs at most\n",
              with.substeps, double(with.stretch), double(without.stretch), (unsigned long long)with.pairs);
  EXPECT_GT(with.substeps, without.substeps);
  EXPECT_LE(with.stretch, without.stretch);
  EXPECT_EQ(with.pairs, 0u);
}

TEST(Contact, AFastFoldAndAYankNeverPassTheSheetThroughItself) {
  // A corner carried across the sheet in a quarter of a second and pressed down, then yanked away
  // hard enough to tear (100 units/s; the grab, bounded, falls behind such a hand)
  const SimParams p = flatCrumple(true);
  const SimState flat = flatState();
  const vec3 far(flat.pos[p.cols * p.rows - 1]);
  std::string text = "0 grab particle 0\n";
  char line[160];
  const vec3 from(flat.pos[0]);
  for (int t = 1; t <= 15; ++t) {
    const float f = float(t) / 15.0f;
    const vec3 q = from + (far - from) * f + vec3(0.0f, 0.5f * std::sin(3.14159265f * f), 0.0f);
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t, q.x, q.y, q.z);
    text += line;
  }
  for (int t = 1; t <= 10; ++t) {
    const vec3 q = far + vec3(0.0f, 0.75f * float(t), -1.5f * float(t));
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", 30 + t, q.x, q.y, q.z);
    text += line;
  }
  text += "41 release\n";
  // Torn triangles stop colliding at once: the layers still never cross. (The stretch limit holds
  // every edge within a percent of its length, short of tearing, so it is off, and the paper tears
  // at 1.5 x its length: the sheet that slides along its layers follows a yank the crumple
  // preset's 2.5 lets through whole.)
  EXPECT_GT(expectContactHolds("fold and yank", text, 90, {"stretch_limit=0", "tear_factor=1.5"}), 0u);
}

TEST(Contact, TheHandCrumplesItIntoABallWithoutPassingItThroughItself) {
  // The middle lifted (half a second), the hand closing round it (half a second), holding, lowering
  // it to the floor and letting go
  const SimParams p = flatCrumple(true);
  const SimState flat = flatState();
  const uint32_t middle = (p.rows / 2) * p.cols + p.cols / 2;
  const vec3 m(flat.pos[middle]);
  const float lift = 0.3f * float(p.rows - 1) * p.spacing;
  std::string text = "0 grab particle " + std::to_string(middle) + "\n";
  char line[160];
  for (int t = 1; t <= 30; ++t) {
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t, m.x, m.y + lift * float(t) / 30.0f, m.z);
    text += line;
  }
  for (int t = 1; t <= 30; ++t) {
    std::snprintf(line, sizeof(line), "%d squeeze %.6f\n", 30 + t, float(t) / 30.0f);
    text += line;
  }
  for (int t = 1; t <= 30; ++t) {
    std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", 90 + t, m.x, m.y + lift * (1.0f - float(t) / 30.0f),
                  m.z);
    text += line;
  }
  text += "121 release\n";
  // (At this pace the repulsion alone also keeps the layers apart: a check that contact breaks nothing)
  EXPECT_EQ(mostPairs(p, text, 180, 5), 0u);
}

TEST(Contact, ASheetForcedThroughItselfUntangles) {
  TENDER_ONE_THREAD_TEST();
  // The hanging sheet's bottom middle dragged forward, up and back through the sheet with the
  // particle repulsion alone, then contact turned on and the sheet let go: where it crosses itself
  // nothing holds it, and it comes apart within a second
  const SimParams p = preset("crumple", {"contact_factor=0"}); // 40 x 60
  CpuSolver solver;
  Simulation sim(p, solver);
  const SimState start = run(sim, 0);
  const uint32_t bottom = (p.rows - 1) * p.cols + p.cols / 2;
  const vec3 b(start.pos[bottom]);
  const float height = float(p.rows - 1) * p.spacing;
  std::string text = "0 grab particle " + std::to_string(bottom) + "\n";
  char line[160];
  auto path = [&](int t0, vec3 from, vec3 to, int ticks) {
    for (int t = 1; t <= ticks; ++t) {
      const vec3 q = from + (to - from) * (float(t) / float(ticks));
      std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t0 + t, q.x, q.y, q.z);
      text += line;
    }
  };
  const vec3 front = b + vec3(0.0f, 0.05f * height, 1.5f), high = b + vec3(0.0f, 0.6f * height, 1.5f);
  path(0, b, front, 10);
  path(10, front, high, 20);
  path(30, high, high - vec3(0.0f, 0.0f, 3.0f), 10);
  text += "41 set contact_factor 0.5\n50 release\n";
  sim.setScript(script(text.c_str()));
  const SimState forced = run(sim, 41);
  EXPECT_GT(intersectingPairs(forced.pos, forced.triangles, forced.triangle_count).pairs, 0u);
  const SimState later = run(sim, 60);
  EXPECT_EQ(intersectingPairs(later.pos, later.triangles, later.triangle_count).pairs, 0u);
  EXPECT_GE(solver.contacts(), 0); // contact is on
}

TEST(Contact, PartingLayersGainNoSpeed) {
  // A sheet folded flat onto itself, its layers a tenth of the contact radius apart and at rest,
  // without gravity, damping, repulsion or bending: the contact parts the layers by moving them,
  // not by speeding them up (the distance constraints alone turn the little strain it makes into
  // motion)
  const SimParams p = flatCrumple(true, {"gravity=0", "damping=1", "collision=off", "dihedral=off", "shear=off"});
  CpuSolver solver;
  Simulation sim(p, solver);
  run(sim, 0);
  const uint32_t fold = p.rows / 2;
  const float gap = 0.1f * p.contactRadius();
  std::vector<glm::vec4>& pos = solver.positions();
  for (uint32_t j = fold + 1; j < p.rows; ++j)
    for (uint32_t i = 0; i < p.cols; ++i) {
      glm::vec4& q = pos[j * p.cols + i];
      const glm::vec4 mirror = pos[(2 * fold - j) * p.cols + i];
      q = glm::vec4(mirror.x, mirror.y + gap, mirror.z, q.w);
    }
  solver.previous() = pos;
  const SimState folded = run(sim, 0);
  EXPECT_EQ(intersectingPairs(folded.pos, folded.triangles, folded.triangle_count).pairs, 0u);
  float fastest = 0.0f;
  for (int t = 0; t < 30; ++t) {
    const SimState s = run(sim, 1);
    fastest = std::max(fastest, computeStats(s, p.substepDt()).max_speed);
  }
  const SimState s = run(sim, 0);
  std::printf("folded layers: fastest particle %.4f units/s\n", double(fastest));
  // A push that left the layers its speed would send them apart at 6.6 units/s; the constraints'
  // settling of the strain it makes is 0.60
  EXPECT_LT(fastest, 1.0f);
  EXPECT_EQ(intersectingPairs(s.pos, s.triangles, s.triangle_count).pairs, 0u);
}

TEST(Contact, ASheetAtRestStaysAtRestAtEveryAcceptedRadius) {
  // At the least, the paper's and the most contact_factor takes, an 8 x 8 `crumple` sheet hanging
  // from its corners and one lying flat on the floor stay at rest: no radius lets the contact push
  // particles that lie still (a radius past sqrt 2 spacings does: 2.9 units/s hanging at 2)
  const ParamInfo info = *paramInfo("contact_factor");
  ASSERT_GT(info.least_on, 0.0);
  for (const float factor : {float(info.least_on), presetParams("crumple")->contact_factor, float(info.hi)})
    for (const bool flat : {false, true}) {
      const std::string radius = "contact_factor=" + std::to_string(factor);
      const SimParams p = flat ? preset("crumple", {"cols=8", "rows=8", "wind=off", "tilt=90", "pins=none",
                                                    "floor_y=-3", "top_y=-3", radius.c_str()})
                               : preset("crumple", {"cols=8", "rows=8", "wind=off", radius.c_str()});
      CpuSolver solver;
      Simulation sim(p, solver);
      const SimState first = run(sim, 30);
      const SimState last = run(sim, 60);
      float moved = 0.0f;
      for (size_t i = 0; i < last.pos.size(); ++i)
        moved = std::max(moved, glm::length(vec3(last.pos[i] - first.pos[i])));
      const float speed = computeStats(last, p.substepDt()).max_speed;
      EXPECT_LT(speed, 1e-3f) << radius << (flat ? " on the floor" : " hanging");
      EXPECT_LT(moved, 1e-3f) << radius << (flat ? " on the floor" : " hanging");
    }
}

TEST(Contact, ASheetFallingAsAWholeIsNotHeldBack) {
  // The receipt let go without air, with contact: its bound alone would cap a step at 0.4 of the
  // contact radius, 0.96 m/s; the frame of the steps (contactFrame: the motion every particle
  // shares) is taken out first, so it falls as freely as without contact, with the same bits; and
  // as no pair's distance changes, the lists of pairs stand from the first build to the last
  uint32_t builds = 0;
  auto fall = [&](const char* contact) {
    const SimParams p = preset("paper", {"air=off", "tilt=90", "floor_y=-100", contact});
    CpuSolver solver;
    Simulation sim(p, solver);
    const SimState s = run(sim, int(0.5f * p.tick_hz));
    builds = solver.contactListBuilds();
    return s;
  };
  const SimState free = fall("contact_factor=0"), bounded = fall("contact_factor=0.5");
  const SimParams p = preset("paper", {"contact_factor=0.5"});
  const float speed = computeStats(bounded, p.substepDt()).max_speed;
  const float cap = SIM_CONTACT_FRACTION * p.contactRadius() * p.tick_hz * float(p.substeps);
  std::printf("falling receipt with contact: %.3f m/s after 0.5 s (the bound's cap: %.3f m/s); the lists built %u "
              "times in %u substeps\n",
              double(speed), double(cap), builds, uint32_t(0.5f * p.tick_hz) * p.substeps);
  EXPECT_GT(speed, 4.0f * cap);
  EXPECT_LE(builds, 2u);
  EXPECT_EQ(hashPositions(free.pos), hashPositions(bounded.pos));
}

TEST(Contact, AStripHeldUnderAFoldIsPulledFree) {
  // An 8 x 12 `tender` sheet that does not tear, its corner yanked 8.5 units away in one tick and
  // let go at tick 30: it swings back and folds over, and the strip by its pin (particle 8, row 1)
  // ends under a fold of the lower sheet, its edge pulling it straight at that layer. A contact
  // that only cut each step in its own half-spaces took all of the pull out and held the edge at
  // 9.08 times its length from tick 60 on; passed on in part (contactPassed), the pull moves the
  // layer, and the strip shortens to its length without the layers crossing
  const SimParams p = preset("tender", {"cols=8", "rows=12", "tear_factor=50"});
  CpuSolver solver;
  Simulation sim(p, solver);
  sim.setScript(script("0 grab particle 95\n1 move 6 -5 6\n30 release\n"));
  uint64_t pairs = 0;
  float stretch = 0.0f;
  for (int t = 10; t <= 240; t += 10) {
    const SimState s = run(sim, 10);
    pairs = std::max(pairs, intersectingPairs(s.pos, s.triangles, s.triangle_count).pairs);
    stretch = computeStats(s, p.substepDt()).max_stretch;
    if (t == 60) std::printf("hooked strip: max stretch %.4f at tick 60", double(stretch));
  }
  std::printf(", %.4f at tick 240; %llu intersecting pairs at most\n", double(stretch), (unsigned long long)pairs);
  EXPECT_GE(solver.contacts(), 0); // contact is on
  EXPECT_LT(stretch, 1.01f);
  EXPECT_EQ(pairs, 0u);
}

// `layers` layers of a side x side grid 0.15 apart, a triangle mesh each: layer l at height gap x l,
// moved by shift x l in its plane
struct Layers {
  std::vector<glm::vec4> pos;
  std::vector<glm::uvec4> triangles;
};
Layers stackedLayers(uint32_t side, uint32_t layers, float gap, glm::vec2 shift) {
  Layers out;
  out.pos.resize(layers * side * side);
  for (uint32_t l = 0; l < layers; ++l)
    for (uint32_t y = 0; y < side; ++y)
      for (uint32_t x = 0; x < side; ++x) {
        const uint32_t i = (l * side + y) * side + x;
        out.pos[i] = glm::vec4(0.15f * float(x) + shift.x * float(l), gap * float(l),
                               0.15f * float(y) + shift.y * float(l), 1.0f);
        if (x + 1 < side && y + 1 < side) {
          out.triangles.push_back(glm::uvec4(i, i + 1, i + side, 0));
          out.triangles.push_back(glm::uvec4(i + 1, i + side + 1, i + side, 0));
        }
      }
  return out;
}

// The contact's uniforms for a radius (its thickness and fixed point as the solver sets them), the
// floor far below
shaderio::SimUniforms contactUniforms(float radius) {
  shaderio::SimUniforms u{};
  const float thickness = radius * SIM_CONTACT_THICKNESS;
  u.contact = glm::vec4(radius, SIM_CONTACT_FRACTION, thickness, SIM_CONTACT_FIXED / thickness);
  u.floor_y = -10.0f;
  return u;
}

// Pair lists kept (Lists::Repaired: standing, turned, by clusters, repaired) against lists built
// whole at every call, on the same positions: the same bounds and pushes, and the same cuts of
// random steps up to 0.3 radius to the pairs' half-spaces (every pair closer than the radius has
// one, so a pair missing from the kept lists shows)
struct KeptAgainstRebuilt {
  WorkerPool pool{2};
  CpuContact rebuilt{pool, CpuContact::Lists::Rebuilt}, kept{pool, CpuContact::Lists::Repaired};
  std::vector<float> bound_a, bound_b, share_a, share_b;
  std::vector<glm::vec4> push_a, push_b, moved, passed_a, passed_b, excess_a, excess_b;

  testing::AssertionResult call(const std::vector<glm::vec4>& pos, const std::vector<glm::vec4>& prev,
                                const std::vector<glm::uvec4>& triangles, const shaderio::SimUniforms& u,
                                std::mt19937& rng) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    rebuilt.computeBounds(pos, prev, triangles, uint32_t(triangles.size()), u, 1, bound_a, push_a);
    kept.computeBounds(pos, prev, triangles, uint32_t(triangles.size()), u, 1, bound_b, push_b);
    moved.resize(pos.size());
    for (size_t i = 0; i < pos.size(); ++i)
      moved[i] = pos[i] + glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * 0.3f * u.contact.x;
    rebuilt.slide(pos, moved, u, passed_a, excess_a, share_a);
    kept.slide(pos, moved, u, passed_b, excess_b, share_b);
    if (!sameBytes(bound_a, bound_b)) return testing::AssertionFailure() << "the bounds differ";
    if (!sameBytes(push_a, push_b)) return testing::AssertionFailure() << "the pushes differ";
    if (!sameBytes(passed_a, passed_b)) return testing::AssertionFailure() << "the passed steps differ";
    if (!sameBytes(excess_a, excess_b)) return testing::AssertionFailure() << "the excesses differ";
    if (!sameBytes(share_a, share_b)) return testing::AssertionFailure() << "the shares differ";
    return testing::AssertionSuccess();
  }
};

TEST(ContactLists, ARepairKeepsEveryPairCloserThanTheRadius) {
  // Two layers of a 16 x 16 grid a radius apart, a triangle mesh of each, and at each call a few
  // particles carried up to half a radius and the rest nudged: lists repaired where particles
  // travelled too far hold every pair closer than the radius (KeptAgainstRebuilt)
  constexpr uint32_t kLayer = 16 * 16;
  const float radius = 0.1f;
  auto [pos, triangles] = stackedLayers(16, 2, radius, glm::vec2(0.0f, 0.05f));
  const shaderio::SimUniforms u = contactUniforms(radius);
  KeptAgainstRebuilt lists;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  uint32_t contacts = 0;
  for (uint32_t call = 0; call < 120; ++call) {
    const std::vector<glm::vec4> prev = pos;
    for (glm::vec4& p : pos) {
      const float reach = rng() % 40 == 0 ? 0.5f * radius : 0.03f * radius;
      p += glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * reach;
    }
    ASSERT_TRUE(lists.call(pos, prev, triangles, u, rng)) << "call " << call;
    contacts += uint32_t(lists.rebuilt.contacts());
  }
  std::printf("%u particles in contact a call; lists built whole %u times, or %u times and repaired %u times\n",
              contacts / 120u, lists.rebuilt.listBuilds(), lists.kept.listBuilds(), lists.kept.listRepairs());
  EXPECT_GT(contacts / 120u, kLayer);
  EXPECT_GT(lists.kept.listRepairs(), 60u);
  EXPECT_EQ(lists.rebuilt.listRepairs(), 0u);
}

TEST(ContactLists, ASheetThatTurnsAndStretchesKeepsItsListsAndEveryPairCloserThanTheRadius) {
  // Two layers of a 40 x 40 grid 0.6 radius apart, one over half of the other, turned about a tilted axis by up to 1.2
  // rad, stretched in their plane by 0.4 % about their middle over the 20th to the 29th call, the upper one slid
  // farther over the lower by two radii from the 40th to the 50th, and every particle nudged: the corners travel
  // hundreds of times the lists' travel, the stretch alone carries particles farther from one another than it lets, and
  // the slide brings new pairs within the radius. The lists stand through the turn (taken out of the travels) and the
  // stretch (clusters next to each other travel alike), not through the slide, and hold every pair closer than the
  // radius (KeptAgainstRebuilt).
  constexpr uint32_t kSide = 40, kCalls = 60;
  const float radius = 0.1f;
  const auto [rest, triangles] = stackedLayers(kSide, 2, 0.6f * radius, glm::vec2(0.075f * kSide, 0.05f));
  const uint32_t n = uint32_t(rest.size());
  vec3 middle(0.0f);
  for (const glm::vec4& p : rest) middle += vec3(p) / float(n);
  const shaderio::SimUniforms u = contactUniforms(radius);
  KeptAgainstRebuilt lists;
  const CpuContact& kept = lists.kept;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const vec3 axis = glm::normalize(vec3(0.3f, 1.0f, 0.2f));
  std::vector<glm::vec4> pos = rest, prev;
  uint64_t contacts = 0;
  float widest = 0.0f;
  uint32_t turned = 0, held = 0; // the calls of the first two phases the lists stood by the turn, the clusters
  for (uint32_t call = 0; call < kCalls; ++call) {
    prev = pos;
    const float t = float(call) / float(kCalls - 1);
    const float stretch = 1.0f + 0.004f * std::clamp((float(call) - 20.0f) / 9.0f, 0.0f, 1.0f);
    const float slide = 2.0f * radius * std::clamp((float(call) - 40.0f) / 10.0f, 0.0f, 1.0f);
    const glm::mat3 turn = glm::mat3(glm::rotate(glm::mat4(1.0f), 1.2f * t, axis));
    for (uint32_t i = 0; i < n; ++i) {
      vec3 d = vec3(rest[i]) - middle;
      d = vec3(d.x * stretch - (i >= n / 2 ? slide : 0.0f), d.y, d.z * stretch);
      const vec3 nudge = vec3(unit(rng), unit(rng), unit(rng)) * 0.01f * radius;
      pos[i] = glm::vec4(middle + turn * d + nudge, 1.0f);
      widest = std::max(widest, glm::length(vec3(pos[i]) - vec3(rest[i])));
    }
    const uint32_t turns = kept.listTurns(), holds = kept.listHolds();
    ASSERT_TRUE(lists.call(pos, prev, triangles, u, rng)) << "call " << call;
    contacts += lists.rebuilt.contacts();
    if (call < 20) turned += kept.listTurns() - turns;
    if (call >= 20 && call < 40) held += kept.listHolds() - holds;
  }
  std::printf("%llu particles in contact a call, travels up to %.2f (%.0f x the lists' travel); lists built %u "
              "times, repaired %u times, kept by the turn %u times and by the clusters %u times in %u calls\n",
              (unsigned long long)(contacts / kCalls), double(widest), double(widest / shaderio::contactTravel(radius)),
              kept.listBuilds(), kept.listRepairs(), kept.listTurns(), kept.listHolds(), kCalls);
  EXPECT_GT(contacts / kCalls, n / 4);
  EXPECT_GT(widest, 100.0f * shaderio::contactTravel(radius));
  EXPECT_GE(turned, 18u);
  EXPECT_GE(held, 15u);
  EXPECT_GE(kept.listBuilds() + kept.listRepairs(), 5u); // the slide
}

TEST(ContactLists, TwoLayersClosingInHaveTheirListsBuiltBeforeTheyMeet) {
  // Two layers of a 24 x 24 grid 100 radii apart, the upper one let down by 6 radii a call until it
  // lies half a radius over the lower, and every particle nudged: each layer travels as one, so
  // clusters next to each other travel alike, and only the spread of the clusters apart
  // (cluster_far_) has the lists built again before a pair comes within the radius
  // (KeptAgainstRebuilt).
  constexpr uint32_t kCalls = 24;
  const float radius = 0.1f, gap = 100.0f * radius;
  const auto [rest, triangles] = stackedLayers(24, 2, gap, glm::vec2(0.0f));
  const uint32_t n = uint32_t(rest.size());
  const shaderio::SimUniforms u = contactUniforms(radius);
  KeptAgainstRebuilt lists;
  const CpuContact& kept = lists.kept;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec4> pos = rest, prev;
  uint64_t contacts = 0;
  for (uint32_t call = 0; call < kCalls; ++call) {
    prev = pos;
    const float drop = std::min(6.0f * radius * float(call), gap - 0.5f * radius);
    for (uint32_t i = 0; i < n; ++i)
      pos[i] = rest[i] + glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * 0.01f * radius -
               glm::vec4(0.0f, i >= n / 2 ? drop : 0.0f, 0.0f, 0.0f);
    ASSERT_TRUE(lists.call(pos, prev, triangles, u, rng)) << "call " << call;
    contacts += lists.rebuilt.contacts();
  }
  std::printf("%llu particles in contact in all; lists built %u times, repaired %u times, kept by the clusters %u "
              "times in %u calls\n",
              (unsigned long long)contacts, kept.listBuilds(), kept.listRepairs(), kept.listHolds(), kCalls);
  EXPECT_GT(contacts, uint64_t(n));
  EXPECT_GE(kept.listHolds(), 4u);
  EXPECT_GE(kept.listBuilds(), 8u);
}

// Three layers of a side x side grid 0.4 radius apart (closer than the thickness: every particle
// pushed), at each call shaken about their rest and one particle in `carried` carried up to half a
// radius in its layer's plane (the lists repaired or built whole): the bounds and pushes are those
// of every particle-triangle and edge-edge pair weighed once, found without a grid, and so are what
// each particle's step is passed by its pairs and the excess and share of that step beyond its pairs'
// half-spaces (slide). A small sheet
// has a small hash table, where two cells of one box are likelier to share a bucket.
void expectBruteForceContact(uint32_t side, uint32_t carried, uint32_t calls) {
  const uint32_t n = 3 * side * side;
  const float radius = 0.1f, thickness = radius * SIM_CONTACT_THICKNESS, r2 = radius * radius;
  const auto [rest, triangles] = stackedLayers(side, 3, 0.4f * radius, glm::vec2(0.05f, 0.0f));
  std::vector<glm::uvec2> edges;
  for (const glm::uvec4& t : triangles)
    for (glm::uvec2 e : {glm::uvec2(t.x, t.y), glm::uvec2(t.y, t.z), glm::uvec2(t.z, t.x)})
      edges.push_back(glm::uvec2(std::min(e.x, e.y), std::max(e.x, e.y)));
  std::sort(edges.begin(), edges.end(), [](glm::uvec2 a, glm::uvec2 b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  const shaderio::SimUniforms u = contactUniforms(radius);
  WorkerPool pool(2);
  CpuContact contact(pool, CpuContact::Lists::Repaired);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec4> pos = rest, prev;
  std::vector<float> bound, want_bound(n);
  std::vector<glm::vec4> push, want_push(n);
  for (uint32_t call = 0; call < calls; ++call) {
    prev = pos;
    for (uint32_t i = 0; i < n; ++i) {
      const float carry = rng() % carried == 0 ? 0.5f * radius : 0.0f;
      pos[i] = rest[i] + glm::vec4(unit(rng) * carry, 0.0f, unit(rng) * carry, 0.0f) +
               glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * 0.03f * radius;
    }
    contact.computeBounds(pos, prev, triangles, uint32_t(triangles.size()), u, 1, bound, push);
    // Every particle then stepped up to 0.3 radius (towards the other layers too): the share of each
    // step its pairs' half-spaces keep, and the excess they take out
    std::vector<glm::vec4> moved(n);
    for (uint32_t i = 0; i < n; ++i)
      moved[i] = pos[i] + glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * 0.3f * radius;
    std::vector<glm::vec4> passed, excess;
    std::vector<float> share;
    contact.slide(pos, moved, u, passed, excess, share);
    auto at = [&](uint32_t i) { return vec3(pos[i]); };
    // Every pair once, without lists or a grid
    std::vector<float> nearest2(n, r2);
    std::vector<glm::ivec4> sums(n, glm::ivec4(0));
    struct Half {
      glm::uvec4 q;
      ContactPair c;
      bool edge;
      uint32_t j;
      shaderio::SlideHalf h;
    };
    std::vector<Half> halves;
    auto weigh = [&](glm::uvec4 q, ContactPair c, bool edge) {
      if (!(c.d2 < r2)) return;
      for (uint32_t j = 0; j < 4; ++j) {
        const shaderio::SlideHalf h =
            shaderio::slideConstraint(at(q.x), at(q.y), at(q.z), at(q.w), c, edge, radius, u.contact.y, j);
        if (h.h.w >= 0.0f) halves.push_back(Half{q, c, edge, j, h});
      }
      for (uint32_t i : {q.x, q.y, q.z, q.w}) nearest2[i] = std::min(nearest2[i], c.d2);
      if (!(c.d2 < thickness * thickness)) return;
      for (uint32_t j = 0; j < 4; ++j) {
        const glm::ivec3 f = shaderio::contactFixed(
            shaderio::contactPush(pos[q.x], pos[q.y], pos[q.z], pos[q.w], c, thickness, j), u.contact.w);
        sums[q[j]] += glm::ivec4(f, 1);
      }
    };
    for (uint32_t v = 0; v < n; ++v)
      for (const glm::uvec4& t : triangles)
        if (v != t.x && v != t.y && v != t.z)
          weigh(glm::uvec4(v, t.x, t.y, t.z), shaderio::pointTriangle(at(v), at(t.x), at(t.y), at(t.z)), false);
    for (size_t a = 0; a < edges.size(); ++a)
      for (size_t b = a + 1; b < edges.size(); ++b) {
        const glm::uvec2 e = edges[a], f = edges[b];
        if (e.x != f.x && e.x != f.y && e.y != f.x && e.y != f.y)
          weigh(glm::uvec4(e, f), shaderio::segmentSegment(at(e.x), at(e.y), at(f.x), at(f.y)), true);
      }
    uint32_t pushed = 0;
    for (uint32_t i = 0; i < n; ++i) {
      want_bound[i] = shaderio::slideBound(nearest2[i], radius, u.contact.y);
      want_push[i] = glm::vec4(
          shaderio::contactPushWithin(shaderio::contactAverage(sums[i], u.contact.w), nearest2[i], radius), 0.0f);
      pushed += sums[i].w > 0 ? 1u : 0u;
    }
    // The half-spaces: what each step passes on to the other side of its pairs (a tenth of its
    // excess, weighed by the other particles' parts in the pair's nearest point, to those that can
    // move), each step with the mean of what it is passed, its excess (the mean, in fixed point) and
    // its share
    auto raw = [&](uint32_t i) { return vec3(moved[i]) - (vec3(pos[i]) + contact.frame()); };
    std::vector<glm::ivec4> passed_sums(n, glm::ivec4(0));
    uint32_t passing = 0;
    for (const Half& a : halves) {
      const vec3 e = shaderio::slideExcess(a.h, raw(a.q[a.j]));
      if (e == vec3(0.0f)) continue;
      ++passing;
      for (uint32_t k = 0; k < 4; ++k) {
        const bool other = a.edge ? (k < 2) != (a.j < 2) : (k == 0) != (a.j == 0);
        if (!other || !(moved[a.q[k]].w > 0.0f)) continue;
        const float wk = std::abs(a.c.w[int(k)]);
        passed_sums[a.q[k]] +=
            glm::ivec4(shaderio::contactFixed(e * (-SIM_CONTACT_PASS_FRACTION * wk), u.contact.w), 1);
      }
    }
    std::vector<glm::vec4> want_passed(n);
    for (uint32_t i = 0; i < n; ++i)
      want_passed[i] = glm::vec4(shaderio::contactAverage(passed_sums[i], u.contact.w), 0.0f);
    auto step = [&](uint32_t i) {
      glm::vec3 x = vec3(moved[i]) + vec3(want_passed[i]);
      x.y = std::max(x.y, std::min(moved[i].y, u.floor_y));
      return x - (vec3(pos[i]) + contact.frame());
    };
    std::vector<glm::ivec4> excess_sums(n, glm::ivec4(0));
    for (const Half& a : halves) {
      const uint32_t i = a.q[a.j];
      const vec3 e = shaderio::slideExcess(a.h, step(i));
      if (e != vec3(0.0f)) excess_sums[i] += glm::ivec4(shaderio::contactFixed(e, u.contact.w), 1);
    }
    std::vector<glm::vec4> want_excess(n);
    std::vector<float> want_share(n, 1.0f);
    for (uint32_t i = 0; i < n; ++i)
      want_excess[i] = glm::vec4(shaderio::contactAverage(excess_sums[i], u.contact.w), 0.0f);
    uint32_t cut = 0;
    for (const Half& a : halves) {
      const uint32_t i = a.q[a.j];
      want_share[i] = std::min(want_share[i], shaderio::slideShare(a.h, step(i) + vec3(want_excess[i])));
    }
    for (uint32_t i = 0; i < n; ++i) cut += want_share[i] < 1.0f || excess_sums[i].w > 0 ? 1u : 0u;
    ASSERT_TRUE(sameBytes(passed, want_passed)) << side << " x " << side << ", call " << call;
    ASSERT_GT(passing, n / 8) << side << " x " << side << ", call " << call;
    ASSERT_TRUE(sameBytes(excess, want_excess)) << side << " x " << side << ", call " << call;
    ASSERT_TRUE(sameBytes(share, want_share)) << side << " x " << side << ", call " << call;
    ASSERT_GT(cut, n / 8) << side << " x " << side << ", call " << call;
    ASSERT_TRUE(sameBytes(bound, want_bound)) << side << " x " << side << ", call " << call;
    ASSERT_TRUE(sameBytes(push, want_push)) << side << " x " << side << ", call " << call;
    ASSERT_GT(pushed, n / 2) << side << " x " << side << ", call " << call;
  }
  std::printf("%u x %u x 3: lists built whole %u times, repaired %u times\n", side, side, contact.listBuilds(),
              contact.listRepairs());
  EXPECT_GT(contact.listRepairs(), calls / 3);
}

TEST(ContactLists, TheBoundsAndPushesAreThoseOfABruteForceSearch) {
  expectBruteForceContact(4, 16, 60);
  expectBruteForceContact(10, 30, 40);
}

TEST(Contact, TheBoundsDoNotDependOnTheThreadCount) {
  const SimParams p = flatCrumple(true);
  const std::string text = fastCrumple(p, flatState());
  CpuOptions one, two;
  one.threads = 1;
  two.threads = 2;
  two.min_chunk = 1; // split every loop
  CpuSolver a(one), b(two);
  Simulation sa(p, a), sb(p, b);
  sa.setScript(script(text.c_str()));
  sb.setScript(script(text.c_str()));
  // (the sheet snatched up and swung round: 20 ticks of the crumple's 40)
  expectIdentical(run(sa, 20), run(sb, 20));
}

} // namespace
} // namespace tender::test
