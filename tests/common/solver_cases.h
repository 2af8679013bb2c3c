#pragma once
/// Behaviour every solver shares, written once: analytic cases, invariants and controls. Each test
/// binary instantiates the suite for its backends (the CPU tests for the reference, the GPU tests
/// for both GPU paths):
///
///   struct MyBackend {
///     static constexpr const char* kName = "cpu";
///     using Fixture = ::testing::Test;            // or a fixture that sets up a device
///     static std::unique_ptr<Solver> make(Fixture&);
///   };
///   INSTANTIATE_TYPED_TEST_SUITE_P(Cpu, SolverCase, ::testing::Types<MyBackend>, BackendName);
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "common/free_fall.h"
#include "core/stats.h"
#include "sim_helpers.h"

namespace tender::test {

/// A solver backend's fixture: make() builds a fresh solver of the backend.
template <class Backend>
class SolverCase : public Backend::Fixture {
public:
  std::unique_ptr<Solver> make() { return Backend::make(*this); }
};

/// Names the instantiations after the backend.
struct BackendName {
  template <class T>
  static std::string GetName(int) {
    return T::kName;
  }
};

TYPED_TEST_SUITE_P(SolverCase);

TYPED_TEST_P(SolverCase, FreeFallMatchesDampedVerlet) {
  // Positions near y = 0 keep float rounding of the Verlet velocity (a position difference) small.
  SimParams p = cloth(
      {"pins=none", "wind=off", "collision=off", "tear_factor=0", "floor_y=-10000", "cols=7", "rows=5", "top_y=0.36"});
  for (int ticks : {5, 60}) {
    auto solver = this->make();
    Simulation sim(p, *solver);
    SimState s = run(sim, ticks);
    const double drop = dampedVerletDrop(p, ticks);
    const auto& topo = sim.topology();
    for (uint32_t i = 0; i < topo.particleCount(); ++i) {
      // 0.2% of the drop: an extra or missing substep alone is 2.5% at 5 ticks, 0.2% at 60.
      EXPECT_NEAR(s.pos[i].y, topo.rest_pos[i].y - drop, 2e-3 * drop) << "particle " << i << ", " << ticks << " ticks";
      EXPECT_NEAR(s.pos[i].x, topo.rest_pos[i].x, 1e-4);
      EXPECT_NEAR(s.pos[i].z, 0.0f, 1e-6);
    }
  }
}

TYPED_TEST_P(SolverCase, HangingSheetSettles) {
  auto solver = this->make();
  Simulation sim(cloth({"wind=off", "cols=12", "rows=16"}), *solver);
  SimState s = run(sim, 360);
  SheetStats st = computeStats(s, sim.params().substepDt());
  EXPECT_LT(st.max_stretch, 1.05f);
  EXPECT_LT(st.max_speed, 0.02f);
  EXPECT_EQ(st.torn, 0u);
  EXPECT_EQ(st.nan_count, 0u);
  // It hangs below its pins, above the floor.
  EXPECT_GT(st.bbox_min.y, sim.params().floor_y);
}

TYPED_TEST_P(SolverCase, PinsNeverMove) {
  auto solver = this->make();
  Simulation sim(cloth({"cols=16", "rows=24"}), *solver);
  sim.setScript(script("0 grab particle 300\n2 move 3 -2 4\n20 release\n"));
  const auto& topo = sim.topology();
  for (int t = 0; t < 40; ++t) {
    sim.tick();
    if (t % 8 != 7) continue;
    SimState s;
    solver->readback(s);
    for (uint32_t i : pinIndices(PinMode::Top3, topo.cols, topo.rows))
      ASSERT_EQ(glm::vec3(s.pos[i]), glm::vec3(topo.rest_pos[i])) << "tick " << t;
  }
}

TYPED_TEST_P(SolverCase, PinsToggleFreesTheSheet) {
  auto solver = this->make();
  Simulation sim(cloth({"wind=off", "cols=12", "rows=16"}), *solver);
  sim.setScript(script("10 pins off\n"));
  SimState s = run(sim, 40);
  EXPECT_LT(s.pos[0].y, sim.topology().rest_pos[0].y - 0.01f);
}

// A 1x2 sheet: particle 0 pinned, particle 1 held by the grab at a given stretch.
template <class Fixture>
uint32_t tornAtStretch(Fixture& f, float factor) {
  auto solver = f.make();
  Simulation sim(cloth({"cols=1", "rows=2", "wind=off", "collision=off"}), *solver);
  glm::vec3 top(sim.topology().rest_pos[0]);
  sim.grabParticle(1);
  sim.moveGrab(top - glm::vec3(0.0f, factor * sim.params().spacing, 0.0f));
  SimState s = run(sim, 10);
  EXPECT_EQ(s.triangle_count, 0u);
  return computeStats(s, sim.params().substepDt()).torn;
}

TYPED_TEST_P(SolverCase, TearSurvivesAt249AndTearsAt251) {
  EXPECT_EQ(tornAtStretch(*this, 2.49f), 0u);
  EXPECT_EQ(tornAtStretch(*this, 2.51f), 1u);
}

TYPED_TEST_P(SolverCase, ZeroTearFactorNeverTears) {
  auto solver = this->make();
  Simulation sim(cloth({"tear_factor=0", "cols=16", "rows=24"}), *solver);
  sim.setScript(script("0 grab particle 383\n1 move 8 -4 8\n"));
  EXPECT_EQ(computeStats(run(sim, 30), 1.0f).torn, 0u);
}

TYPED_TEST_P(SolverCase, YankTearsAndCompactsCleanly) {
  auto solver = this->make();
  Simulation sim(crumpleSheet({"cols=12", "rows=16", "wind=on"}), *solver);
  sim.setScript(script("0 grab particle 191\n1 move 6 -5 6\n20 release\n"));
  SimState s = run(sim, 40);
  SheetStats st = computeStats(s, sim.params().substepDt());
  const SheetTopology& topo = sim.topology();
  EXPECT_GT(st.torn, 0u);
  EXPECT_LT(st.triangles, topo.triangleCount());
  EXPECT_EQ(st.nan_count, 0u);
  // Shear constraints never tear by stretch; they go with the triangles they stand on, which the
  // yank takes from a few quads, so that no live constraint ties two pieces of the mesh together.
  EXPECT_LT(st.constraints[SIM_KIND_SHEAR], topo.kind_counts[SIM_KIND_SHEAR]);
  EXPECT_EQ(tiesAcrossPieces(s), 0u);
  // Colour ranges stay contiguous, keep their first slot, and hold only live constraints.
  uint32_t live = 0;
  for (size_t c = 0; c < s.colors.size(); ++c) {
    EXPECT_EQ(s.colors[c].first, topo.colors[c].first);
    EXPECT_LE(s.colors[c].count, topo.colors[c].count);
    for (uint32_t k = s.colors[c].first; k < s.colors[c].first + s.colors[c].count; ++k)
      EXPECT_EQ(s.torn[constraintId(s.constraints[k])], 0u);
    live += s.colors[c].count;
  }
  uint32_t torn = 0;
  for (uint32_t t : s.torn) torn += t;
  EXPECT_EQ(live + torn, topo.constraintCount());
  // Every remaining triangle still has both structural edges.
  for (uint32_t k = 0; k < s.triangle_count; ++k) {
    glm::uvec2 e = topo.tri_edges[s.triangles[k].w];
    EXPECT_FALSE(s.torn[e.x] || s.torn[e.y]);
  }
}

TYPED_TEST_P(SolverCase, NoNaNUnderWindAndCollision) {
  auto solver = this->make();
  Simulation sim(crumpleSheet({"cols=10", "rows=14", "wind=on", "pins=none"}), *solver);
  SimState s = run(sim, 120);
  SheetStats st = computeStats(s, sim.params().substepDt());
  EXPECT_EQ(st.nan_count, 0u);
  for (const glm::vec4& n : s.normal) EXPECT_NEAR(glm::length(glm::vec3(n)), 1.0f, 1e-4f);
}

TYPED_TEST_P(SolverCase, TwoRunsAreBitwiseIdentical) {
  auto once = [this] {
    auto solver = this->make();
    Simulation sim(paperSheet({"wind=on", "cols=20", "rows=30"}), *solver);
    sim.setScript(script("0 grab particle 599\n1 move 5 -6 5\n20 release\n40 grab particle 300\n41 move 0 0 3\n"));
    return run(sim, 80);
  };
  SimState a = once(), b = once();
  ASSERT_EQ(a.pos.size(), 600u);
  EXPECT_TRUE(sameBytes(a.pos, b.pos));
  EXPECT_TRUE(sameBytes(a.prev, b.prev));
  EXPECT_EQ(a.torn, b.torn);
}

TYPED_TEST_P(SolverCase, ResetAnimatesBackOverThirtyFrames) {
  auto solver = this->make();
  Simulation sim(cloth({"cols=8", "rows=12"}), *solver);
  sim.setScript(script("0 grab particle 95\n1 move 6 -5 6\n20 reset\n"));
  SimState torn = run(sim, 20);
  ASSERT_GT(computeStats(torn, 1.0f).torn, 0u);
  sim.tick(); // the reset event applies, first frame
  EXPECT_TRUE(sim.resetting());
  run(sim, SIM_RESET_FRAMES - 1);
  EXPECT_FALSE(sim.resetting());
  SimState s = run(sim, 0);
  for (uint32_t i = 0; i < s.pos.size(); ++i) ASSERT_EQ(glm::vec3(s.pos[i]), glm::vec3(sim.topology().rest_pos[i]));
  EXPECT_EQ(computeStats(s, 1.0f).torn, 0u);
  EXPECT_EQ(s.triangle_count, sim.topology().triangleCount());
  EXPECT_EQ(sim.grabbed(), SIM_NONE);
}

TYPED_TEST_P(SolverCase, PauseFreezesTheState) {
  auto solver = this->make();
  Simulation sim(cloth({"cols=8", "rows=12"}), *solver);
  sim.setScript(script("5 pause on\n10 pause off\n"));
  SimState a = run(sim, 6);
  SimState b = run(sim, 4);
  ASSERT_EQ(a.pos.size(), 96u);
  EXPECT_TRUE(sameBytes(a.pos, b.pos));
  EXPECT_EQ(sim.physicsTicks(), 5u);
  run(sim, 2); // tick 10 unpauses
  EXPECT_EQ(sim.physicsTicks(), 7u);
}

TYPED_TEST_P(SolverCase, AccumulatorClampsFrameTime) {
  auto solver = this->make();
  // The seeds' cloth on tender-low's grid, ticking at 120 Hz
  Simulation sim(cloth({"cols=24", "rows=36", "spacing=0.24260871"}), *solver);
  EXPECT_EQ(sim.advance(1.0f / 60.0f), 2); // two 120 Hz ticks in a 60 Hz frame
  EXPECT_EQ(sim.advance(5.0f), 3);         // 5 s clamps to 33 ms: three ticks, remainder kept
  EXPECT_EQ(sim.physicsTicks(), 5u);
  EXPECT_EQ(sim.advance(5.0f, 6), 1); // no step past step 6 (the demo's --quit-at)
  EXPECT_EQ(sim.advance(5.0f, 6), 0);
  EXPECT_EQ(sim.frameCount(), 6u);
}

TYPED_TEST_P(SolverCase, DragReleaseKeepsMomentum) {
  float moved[2] = {0.0f, 0.0f};
  for (ReleaseMode mode : {ReleaseMode::ZeroVelocity, ReleaseMode::DragVelocity}) {
    auto solver = this->make();
    // A single particle: nothing but the release decides how it moves on.
    SimParams p = crumpleSheet({"pins=none", "gravity=0", "wind=off", "cols=1", "rows=1"});
    p.release = mode;
    Simulation sim(p, *solver);
    sim.grabParticle(0);
    glm::vec3 start = sim.grabTarget();
    for (int t = 1; t <= 10; ++t) {
      sim.moveGrab(start + glm::vec3(0.05f * float(t), 0.0f, 0.0f)); // 3 units/s at 60 Hz
      sim.tick();
    }
    sim.release();
    SimState s = run(sim, 20);
    moved[mode == ReleaseMode::DragVelocity] = s.pos[0].x - (start.x + 0.5f);
  }
  // Drag velocity 3 units/s, damped 0.995 per substep at 480 substeps/s: ~0.69 units in 20 ticks.
  EXPECT_EQ(moved[0], 0.0f);
  EXPECT_NEAR(moved[1], 3.0f / (480.0f * 0.005f) * (1.0f - std::pow(0.995f, 160.0f)), 0.05f);
}

TYPED_TEST_P(SolverCase, PickFindsTheNearestParticleAndWhereItIs) {
  auto solver = this->make();
  Simulation sim(cloth({"cols=16", "rows=24"}), *solver);
  // Equidistant particles (at rest, the same distance from the ray): the smaller index wins.
  const glm::vec3 mid = 0.5f * (glm::vec3(sim.topology().rest_pos[200]) + glm::vec3(sim.topology().rest_pos[201]));
  auto tie = solver->pick(mid + glm::vec3(0.0f, 0.0f, 10.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.6f);
  EXPECT_EQ(tie.index, 200u);
  SimState s = run(sim, 20); // the sheet moves: its positions differ from the rest positions
  const glm::vec3 target(s.pos[200]);
  ASSERT_NE(target, glm::vec3(sim.topology().rest_pos[200]));
  auto hit = solver->pick(target + glm::vec3(0.01f, 0.0f, 10.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.6f);
  EXPECT_EQ(hit.index, 200u);
  EXPECT_NEAR(hit.t, 10.0f, 1e-4f);
  EXPECT_EQ(glm::vec3(hit.pos), target);
  EXPECT_EQ(hit.pos.w, s.pos[200].w);
  auto miss = solver->pick(glm::vec3(50.0f, 0.0f, 10.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.6f);
  EXPECT_EQ(miss.index, SIM_NONE);
  // A grab by ray starts at the picked particle's position.
  EXPECT_TRUE(sim.grabRay(target + glm::vec3(0.0f, 0.0f, 5.0f), glm::vec3(0.0f, 0.0f, -1.0f)));
  EXPECT_EQ(sim.grabbed(), 200u);
  EXPECT_EQ(solver->particlePosition(200), target);
  // Several positions in one read-back: a few (the camera follow's 9) and more than a small
  // buffer holds, in the order asked
  for (uint32_t count : {9u, 40u}) {
    std::vector<uint32_t> indices;
    for (uint32_t k = 0; k < count; ++k) indices.push_back((k * 37u + 5u) % uint32_t(s.pos.size()));
    const std::vector<glm::vec3> got = solver->particlePositions(indices);
    ASSERT_EQ(got.size(), indices.size());
    for (uint32_t k = 0; k < count; ++k) EXPECT_EQ(got[k], glm::vec3(s.pos[indices[k]])) << k;
  }
}

REGISTER_TYPED_TEST_SUITE_P(SolverCase, FreeFallMatchesDampedVerlet, HangingSheetSettles, PinsNeverMove,
                            PinsToggleFreesTheSheet, TearSurvivesAt249AndTearsAt251, ZeroTearFactorNeverTears,
                            YankTearsAndCompactsCleanly, NoNaNUnderWindAndCollision, TwoRunsAreBitwiseIdentical,
                            ResetAnimatesBackOverThirtyFrames, PauseFreezesTheState, AccumulatorClampsFrameTime,
                            DragReleaseKeepsMomentum, PickFindsTheNearestParticleAndWhereItIs);

} // namespace tender::test
