// Physics of the CPU reference: the behaviour every solver shares (tests/common/solver_cases.h)
// on the plain scalar reference and on the SIMD kernels over threads, and what only the CPU
// solver lets a test do (set positions directly).
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "common/sim_helpers.h"
#include "common/solver_cases.h"
#include "core/stats.h"
#include "cpu/cpu_solver.h"

using namespace tender;
using namespace tender::test;

namespace {

/// The plain reference: one thread, scalar loops.
struct CpuReference {
  static constexpr const char* kName = "reference";
  using Fixture = ::testing::Test;
  static std::unique_ptr<Solver> make(Fixture&) {
    return std::make_unique<CpuSolver>(
        CpuOptions{.threads = 1, .min_chunk = 0, .candidate_lists = true, .simd = false});
  }
};
/// SIMD kernels on two threads, every loop split (min_chunk 1).
struct CpuSimdThreads {
  static constexpr const char* kName = "simd_2threads";
  using Fixture = ::testing::Test;
  static std::unique_ptr<Solver> make(Fixture&) {
    return std::make_unique<CpuSolver>(CpuOptions{.threads = 2, .min_chunk = 1, .candidate_lists = true, .simd = true});
  }
};

} // namespace

namespace tender::test {
using CpuBackends = ::testing::Types<CpuReference, CpuSimdThreads>;
INSTANTIATE_TYPED_TEST_SUITE_P(Cpu, SolverCase, CpuBackends, BackendName);
} // namespace tender::test

TEST(Verlet, ChangingTheSubstepsKeepsTheVelocity) {
  TENDER_ONE_THREAD_TEST();
  // A sheet falling freely (no air, no damping, no floor in reach), its substeps doubled or halved
  // mid-fall by a `set` event: Verlet keeps the velocity as the step of the last substep, so the
  // first substep after the change rescales it to the new substep's length; the fall goes on at
  // the speed it had, gravity adding its own (without the rescale it doubles or halves). With
  // contact on, its frame (the motion the sheet shares, taken out of each step before the bound)
  // takes the same rescale: the last substep's step carried to the new length (halved, the
  // substeps' steps were cut by the bound to 1.77 m/s where the sheet falls at 2.54)
  for (const char* change : {"30 set substeps 16\n", "30 set substeps 4\n"})
    for (const char* contact : {"contact_factor=0", "contact_factor=0.5"}) {
      const std::vector<std::string> keys = {"air=off", "tilt=90", "floor_y=-1000", "damping=1", "substeps=8", contact};
      CpuSolver kept_solver, changed_solver;
      Simulation kept(receiptWithContact(keys), kept_solver), changed(receiptWithContact(keys), changed_solver);
      changed.setScript(script(change));
      run(kept, 31);
      run(changed, 31);
      ASSERT_NE(changed.params().substeps, kept.params().substeps) << change;
      const SimState a = run(kept, 0), b = run(changed, 0);
      const float va = computeStats(a, kept.params().substepDt()).max_speed,
                  vb = computeStats(b, changed.params().substepDt()).max_speed;
      std::printf("%s%s: falling at %.4f m/s with the substeps kept, %.4f changed\n", change, contact, double(va),
                  double(vb));
      EXPECT_GT(va, 0.4f);
      EXPECT_NEAR(vb, va, 1e-3f * va) << change << contact;
    }
}

TEST(Degenerate, SheetsOneParticleWideOrLongTearHangAndCrumple) {
  // 1 x N, N x 1, 1 x 1 and 2 x 2 sheets with every rule that walks the grid: hinges and creases
  // (crumple), the stretch limit, the hand's squeeze, a yank that tears, and contact. A sheet one
  // particle wide has edges no triangle holds (edgeTriangles took its column edges for row edges
  // and read past the triangles: a crash). Each runs, and stays finite; the GPU's paths give the
  // same bits (Parity.DegenerateSheetsWithEveryRule).
  for (const auto& [cols, rows] :
       {std::pair{1, 10}, std::pair{10, 1}, std::pair{1, 3}, std::pair{1, 1}, std::pair{2, 2}}) {
    for (const char* p : {"tender", "crumple"}) {
      const SimParams params =
          preset(p, {("cols=" + std::to_string(cols)).c_str(), ("rows=" + std::to_string(rows)).c_str(),
                     "stretch_limit=1.01", "contact_factor=0.5", "wind=off"});
      const uint32_t last = uint32_t(cols * rows - 1);
      const std::string text =
          "0 grab particle " + std::to_string(last) + "\n1 move 0 0 0\n2 squeeze 1\n" + "8 move 6 -4 5\n14 release\n";
      CpuSolver cpu;
      Simulation sim(params, cpu);
      sim.setScript(script(text.c_str()));
      const SimState s = run(sim, 20);
      ASSERT_EQ(s.pos.size(), size_t(cols * rows)) << cols << "x" << rows << " " << p;
      for (const glm::vec4& q : s.pos)
        ASSERT_TRUE(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z)) << cols << "x" << rows << " " << p;
    }
  }
}

TEST(Collision, FoldedSheetKeepsLayersApart) {
  for (bool collide : {false, true}) {
    CpuSolver cpu;
    // No bend constraints: nothing but collision resists the fold.
    Simulation sim(cloth({"cols=12", "rows=12", "pins=none", "wind=off", "gravity=0", "tear_factor=0", "bend=off",
                          collide ? "collision=on" : "collision=off"}),
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
