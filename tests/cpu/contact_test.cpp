// Penetration-free self-contact (shaders/shared/contact.h, cpu/cpu_contact.h) in scripted scenes
// judged from outside by the exact triangle-triangle intersection count (core/intersections.h):
// fast crumples, folds, yanks, tosses and the hand's ball, untangling, and a sheet at rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common/fast_crumple.h"
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
using shaderio::NearestPoints;

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

/// The demo's toss on a 20 x 30 `crumple` sheet lying on its floor: its middle carried off 0.32
/// units a tick for 60 ticks, then let go; 30 ticks more. The most stretch, the most substeps of a
/// tick and the most intersecting pairs (every 10 ticks).
struct Toss {
  float stretch = 0.0f;
  uint32_t substeps = 0;
  uint64_t pairs = 0;
};
Toss toss(const char* contact_factor) {
  const SimParams p = crumpleSheet({"cols=20", "rows=30", "tilt=90", "pins=none", "wind=off", "floor_y=-3",
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
  const SimParams p = paperSheet({"contact_settle=16"}); // 40 x 60; the settle's sweeps once contact is on
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
  for (const float factor : {float(info.least_on), crumpleSheet().contact_factor, float(info.hi)})
    for (const bool flat : {false, true}) {
      const std::string radius = "contact_factor=" + std::to_string(factor);
      const SimParams p = flat ? crumpleSheet({"cols=8", "rows=8", "wind=off", "tilt=90", "pins=none", "floor_y=-3",
                                               "top_y=-3", radius.c_str()})
                               : crumpleSheet({"cols=8", "rows=8", "wind=off", radius.c_str()});
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
    const SimParams p = receiptWithContact({"air=off", "tilt=90", "floor_y=-100", contact});
    CpuSolver solver;
    Simulation sim(p, solver);
    const SimState s = run(sim, int(0.5f * p.tick_hz));
    builds = solver.contactListBuilds();
    return s;
  };
  const SimState free = fall("contact_factor=0"), bounded = fall("contact_factor=0.5");
  const SimParams p = receiptWithContact();
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
  // layer, and the strip shortens to its length by tick 120 without the layers crossing
  const SimParams p = clothWithContact({"cols=8", "rows=12", "tear_factor=50"});
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
    if (t == 120) {
      EXPECT_LT(stretch, 1.01f) << "not freed by tick 120";
    }
  }
  std::printf(", %.4f at tick 240; %llu intersecting pairs at most\n", double(stretch), (unsigned long long)pairs);
  EXPECT_GE(solver.contacts(), 0); // contact is on
  EXPECT_LT(stretch, 1.01f);
  EXPECT_EQ(pairs, 0u);
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
  const SimState threaded = run(sb, 20);
  if (kComparesThreadCounts) expectIdentical(run(sa, 20), threaded);
}

} // namespace
} // namespace tender::test
