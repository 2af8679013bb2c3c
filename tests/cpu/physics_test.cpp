// Physics of the CPU reference: analytic cases and invariants.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/free_fall.h"
#include "core/simulation.h"
#include "core/stats.h"
#include "cpu/cpu_solver.h"

using namespace tender;

namespace {

SimParams preset(const char* name, std::initializer_list<const char*> sets = {}) {
  SimParams p = *presetParams(name);
  for (const char* s : sets) {
    auto err = applyOverride(p, s);
    EXPECT_FALSE(err) << *err;
  }
  EXPECT_FALSE(validate(p));
  return p;
}

SimState run(Simulation& sim, int ticks) {
  for (int t = 0; t < ticks; ++t) sim.tick();
  SimState s;
  sim.solver().readback(s);
  return s;
}

InputScript script(const char* text) {
  std::string err;
  auto s = parseScript(text, err);
  EXPECT_TRUE(s) << err;
  return s ? *s : InputScript{};
}

} // namespace

TEST(Physics, FreeFallMatchesDampedVerlet) {
  // Positions near y = 0 keep float rounding of the Verlet velocity (a position difference) small.
  SimParams p = preset("tender", {"pins=none", "wind=off", "collision=off", "tear_factor=0", "floor_y=-10000", "cols=7",
                                  "rows=5", "top_y=0.36"});
  for (int ticks : {5, 60}) {
    CpuSolver cpu;
    Simulation sim(p, cpu);
    SimState s = run(sim, ticks);
    const double drop = test::dampedVerletDrop(p, ticks);
    const auto& topo = sim.topology();
    for (uint32_t i = 0; i < topo.particleCount(); ++i) {
      // 0.2% of the drop: an extra or missing substep alone is 2.5% at 5 ticks, 0.2% at 60.
      EXPECT_NEAR(s.pos[i].y, topo.rest_pos[i].y - drop, 2e-3 * drop) << "particle " << i << ", " << ticks << " ticks";
      EXPECT_NEAR(s.pos[i].x, topo.rest_pos[i].x, 1e-4);
      EXPECT_NEAR(s.pos[i].z, 0.0f, 1e-6);
    }
  }
}

TEST(Physics, HangingSheetSettles) {
  CpuSolver cpu;
  Simulation sim(preset("tender", {"wind=off"}), cpu);
  SimState s = run(sim, 600);
  SheetStats st = computeStats(s, sim.params().substepDt());
  EXPECT_LT(st.max_stretch, 1.05f);
  EXPECT_LT(st.max_speed, 0.02f);
  EXPECT_EQ(st.torn, 0u);
  EXPECT_EQ(st.nan_count, 0u);
  // It hangs below its pins, above the floor.
  EXPECT_GT(st.bbox_min.y, sim.params().floor_y);
}

TEST(Physics, PinsNeverMove) {
  CpuSolver cpu;
  Simulation sim(preset("tender"), cpu);
  sim.setScript(script("0 grab particle 1000\n2 move 3 -2 4\n30 release\n"));
  const auto& topo = sim.topology();
  for (int t = 0; t < 90; ++t) {
    sim.tick();
    for (uint32_t i : pinIndices(PinMode::Top3, topo.cols, topo.rows))
      ASSERT_EQ(glm::vec3(cpu.positions()[i]), glm::vec3(topo.rest_pos[i])) << "tick " << t;
  }
}

TEST(Physics, PinsToggleFreesTheSheet) {
  CpuSolver cpu;
  Simulation sim(preset("tender", {"wind=off"}), cpu);
  sim.setScript(script("10 pins off\n"));
  SimState s = run(sim, 40);
  EXPECT_LT(s.pos[0].y, sim.topology().rest_pos[0].y - 0.01f);
}

// A 1x2 sheet: particle 0 pinned, particle 1 held by the grab at a given stretch.
static uint32_t tornAtStretch(float factor) {
  CpuSolver cpu;
  Simulation sim(preset("tender", {"cols=1", "rows=2", "wind=off", "collision=off"}), cpu);
  glm::vec3 top(sim.topology().rest_pos[0]);
  sim.grabParticle(1);
  sim.moveGrab(top - glm::vec3(0.0f, factor * sim.params().spacing, 0.0f));
  SimState s = run(sim, 10);
  EXPECT_EQ(s.triangle_count, 0u);
  return computeStats(s, sim.params().substepDt()).torn;
}

TEST(Tear, SurvivesAt249AndTearsAt251) {
  EXPECT_EQ(tornAtStretch(2.49f), 0u);
  EXPECT_EQ(tornAtStretch(2.51f), 1u);
}

TEST(Tear, ZeroFactorNeverTears) {
  CpuSolver cpu;
  Simulation sim(preset("tender", {"tear_factor=0"}), cpu);
  sim.setScript(script("0 grab particle 1535\n1 move 8 -4 8\n"));
  EXPECT_EQ(computeStats(run(sim, 30), 1.0f).torn, 0u);
}

TEST(Tear, ScriptedYankTearsTheSheet) {
  CpuSolver cpu;
  Simulation sim(preset("tender"), cpu);
  sim.setScript(script("0 grab particle 1535\n1 move 6 -5 6\n30 release\n"));
  SimState s = run(sim, 60);
  SheetStats st = computeStats(s, sim.params().substepDt());
  EXPECT_GT(st.torn, 0u);
  EXPECT_LT(st.triangles, sim.topology().triangleCount());
  EXPECT_EQ(st.nan_count, 0u);
  // Only structural and bend constraints tear; shear survives.
  EXPECT_EQ(st.constraints[SIM_KIND_SHEAR], sim.topology().kind_counts[SIM_KIND_SHEAR]);
  // Compaction keeps colour ranges contiguous and holds only live constraints.
  for (size_t c = 0; c < s.colors.size(); ++c) {
    EXPECT_EQ(s.colors[c].first, sim.topology().colors[c].first);
    EXPECT_LE(s.colors[c].count, sim.topology().colors[c].count);
    for (uint32_t k = s.colors[c].first; k < s.colors[c].first + s.colors[c].count; ++k)
      EXPECT_EQ(s.torn[constraintId(s.constraints[k])], 0u);
  }
  // Every remaining triangle still has both structural edges.
  for (uint32_t k = 0; k < s.triangle_count; ++k) {
    glm::uvec2 e = sim.topology().tri_edges[s.triangles[k].w];
    EXPECT_FALSE(s.torn[e.x] || s.torn[e.y]);
  }
}

TEST(Collision, FoldedSheetKeepsLayersApart) {
  for (bool collide : {false, true}) {
    CpuSolver cpu;
    // No bend constraints: nothing but collision resists the fold.
    Simulation sim(preset("tender", {"cols=12", "rows=12", "pins=none", "wind=off", "gravity=0", "tear_factor=0",
                                     "bend=off", collide ? "collision=on" : "collision=off"}),
                   cpu);
    // Fold the lower half back over the upper half, 0.08 behind it (closer than 1.2 x spacing).
    auto& pos = cpu.positions();
    const auto& topo = sim.topology();
    for (uint32_t j = 6; j < 12; ++j)
      for (uint32_t i = 0; i < 12; ++i) {
        glm::vec4 mirror = topo.rest_pos[(11 - j) * 12 + i];
        pos[j * 12 + i] = glm::vec4(mirror.x, mirror.y, -0.08f, 1.0f);
      }
    cpu.previous() = pos;
    SimState s = run(sim, 60);
    float closest = 1e9f;
    for (uint32_t a = 0; a < 144; ++a)
      for (uint32_t b = a + 1; b < 144; ++b)
        if (!topo.adjacent(a, b)) closest = std::min(closest, glm::length(glm::vec3(s.pos[a] - s.pos[b])));
    if (collide)
      EXPECT_GT(closest, 0.85f * sim.params().collisionRadius());
    else
      EXPECT_LT(closest, 0.1f); // without collision the layers stay interpenetrating
  }
}

TEST(Determinism, TwoRunsAreBitwiseIdentical) {
  auto once = [] {
    CpuSolver cpu;
    Simulation sim(preset("crumple", {"wind=on"}), cpu);
    sim.setScript(script("0 grab particle 2399\n1 move 5 -6 5\n20 release\n40 grab particle 1200\n41 move 0 0 3\n"));
    return run(sim, 80);
  };
  SimState a = once(), b = once();
  ASSERT_EQ(a.pos.size(), b.pos.size());
  EXPECT_EQ(0, std::memcmp(a.pos.data(), b.pos.data(), a.pos.size() * sizeof(glm::vec4)));
  EXPECT_EQ(a.torn, b.torn);
}

TEST(Controls, ResetAnimatesBackOverThirtyFrames) {
  CpuSolver cpu;
  Simulation sim(preset("tender"), cpu);
  sim.setScript(script("0 grab particle 1535\n1 move 6 -5 6\n30 reset\n"));
  run(sim, 30);
  SimState before = run(sim, 0);
  ASSERT_GT(computeStats(before, 1.0f).torn, 0u);
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

TEST(Controls, PauseFreezesTheState) {
  CpuSolver cpu;
  Simulation sim(preset("tender"), cpu);
  sim.setScript(script("10 pause on\n20 pause off\n"));
  SimState a = run(sim, 11);
  SimState b = run(sim, 9);
  EXPECT_EQ(0, std::memcmp(a.pos.data(), b.pos.data(), a.pos.size() * sizeof(glm::vec4)));
  EXPECT_EQ(sim.physicsTicks(), 10u);
  run(sim, 2); // tick 20 unpauses
  EXPECT_EQ(sim.physicsTicks(), 12u);
}

TEST(Controls, AccumulatorClampsFrameTime) {
  CpuSolver cpu;
  Simulation sim(preset("tender-low"), cpu);
  EXPECT_EQ(sim.advance(1.0f / 60.0f), 2); // two 120 Hz ticks in a 60 Hz frame
  EXPECT_EQ(sim.advance(5.0f), 3);         // 5 s clamps to 33 ms: three ticks, remainder kept
  EXPECT_EQ(sim.physicsTicks(), 5u);
}

TEST(Controls, DragReleaseKeepsMomentum) {
  float moved[2] = {0.0f, 0.0f};
  for (ReleaseMode mode : {ReleaseMode::ZeroVelocity, ReleaseMode::DragVelocity}) {
    CpuSolver cpu;
    // A single particle: nothing but the release decides how it moves on.
    SimParams p = preset("crumple", {"pins=none", "gravity=0", "wind=off", "cols=1", "rows=1"});
    p.release = mode;
    Simulation sim(p, cpu);
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

TEST(Pick, NearestParticleWithinRadius) {
  CpuSolver cpu;
  Simulation sim(preset("tender"), cpu);
  glm::vec3 target(sim.topology().rest_pos[700]);
  auto hit = cpu.pick(target + glm::vec3(0.01f, 0.0f, 10.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.6f);
  EXPECT_EQ(hit.index, 700u);
  EXPECT_NEAR(hit.t, 10.0f, 1e-4f);
  auto miss = cpu.pick(glm::vec3(50.0f, 0.0f, 10.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.6f);
  EXPECT_EQ(miss.index, SIM_NONE);
  EXPECT_TRUE(sim.grabRay(target + glm::vec3(0.0f, 0.0f, 5.0f), glm::vec3(0.0f, 0.0f, -1.0f)));
  EXPECT_EQ(sim.grabbed(), 700u);
}
