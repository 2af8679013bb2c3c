// Behaviour both solvers share, one typed test body run against the CPU reference and the GPU.
#include <cmath>
#include <cstring>

#include "core/free_fall.h"
#include "core/stats.h"
#include "cpu/cpu_solver.h"
#include "gpu/gpu_solver.h"
#include "gpu_test_env.h"

using namespace tender;
using namespace tender::test;

namespace {

struct CpuBackend {
  static constexpr bool kGpu = false;
  static std::unique_ptr<Solver> make(gpu::VulkanContext*) { return std::make_unique<CpuSolver>(); }
};
struct GpuBackend {
  static constexpr bool kGpu = true;
  static std::unique_ptr<Solver> make(gpu::VulkanContext* ctx) { return std::make_unique<gpu::GpuSolver>(*ctx); }
};

template <class Backend>
class BothSolvers : public GpuTest {
protected:
  void SetUp() override {
    if (Backend::kGpu) GpuTest::SetUp();
  }

public:
  std::unique_ptr<Solver> make() { return Backend::make(ctx_); }
};

struct BackendName {
  template <class T>
  static std::string GetName(int) {
    return T::kGpu ? "gpu" : "cpu";
  }
};

using Backends = ::testing::Types<CpuBackend, GpuBackend>;
TYPED_TEST_SUITE(BothSolvers, Backends, BackendName);

} // namespace

TYPED_TEST(BothSolvers, FreeFallMatchesDampedVerlet) {
  SimParams p = preset("tender", {"pins=none", "wind=off", "collision=off", "tear_factor=0", "floor_y=-10000", "cols=7",
                                  "rows=5", "top_y=0.36"});
  const int ticks = 30;
  auto solver = this->make();
  Simulation sim(p, *solver);
  SimState s = run(sim, ticks);
  const double drop = test::dampedVerletDrop(p, ticks);
  const auto& topo = sim.topology();
  for (uint32_t i = 0; i < topo.particleCount(); ++i) {
    EXPECT_NEAR(s.pos[i].y, topo.rest_pos[i].y - drop, 2e-3 * drop) << "particle " << i;
    EXPECT_NEAR(s.pos[i].x, topo.rest_pos[i].x, 1e-4);
    EXPECT_NEAR(s.pos[i].z, 0.0f, 1e-6);
  }
}

TYPED_TEST(BothSolvers, PinsNeverMove) {
  auto solver = this->make();
  Simulation sim(preset("tender", {"cols=16", "rows=24"}), *solver);
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

// A 1x2 sheet: particle 0 pinned, particle 1 held by the grab at a given stretch.
template <class Fixture>
uint32_t tornAtStretch(Fixture& f, float factor) {
  auto solver = f.make();
  Simulation sim(preset("tender", {"cols=1", "rows=2", "wind=off", "collision=off"}), *solver);
  glm::vec3 top(sim.topology().rest_pos[0]);
  sim.grabParticle(1);
  sim.moveGrab(top - glm::vec3(0.0f, factor * sim.params().spacing, 0.0f));
  SimState s = run(sim, 10);
  EXPECT_EQ(s.triangle_count, 0u);
  return computeStats(s, sim.params().substepDt()).torn;
}

TYPED_TEST(BothSolvers, TearSurvivesAt249AndTearsAt251) {
  EXPECT_EQ(tornAtStretch(*this, 2.49f), 0u);
  EXPECT_EQ(tornAtStretch(*this, 2.51f), 1u);
}

TYPED_TEST(BothSolvers, HangingSheetSettles) {
  auto solver = this->make();
  Simulation sim(preset("tender", {"wind=off", "cols=12", "rows=16"}), *solver);
  SimState s = run(sim, 360);
  SheetStats st = computeStats(s, sim.params().substepDt());
  EXPECT_LT(st.max_stretch, 1.05f);
  EXPECT_LT(st.max_speed, 0.02f);
  EXPECT_EQ(st.torn, 0u);
  EXPECT_EQ(st.nan_count, 0u);
  EXPECT_GT(st.bbox_min.y, sim.params().floor_y);
}

TYPED_TEST(BothSolvers, YankTearsAndCompactsCleanly) {
  auto solver = this->make();
  Simulation sim(preset("crumple", {"cols=12", "rows=16", "wind=on"}), *solver);
  sim.setScript(script("0 grab particle 191\n1 move 6 -5 6\n20 release\n"));
  SimState s = run(sim, 40);
  SheetStats st = computeStats(s, sim.params().substepDt());
  const SheetTopology& topo = sim.topology();
  EXPECT_GT(st.torn, 0u);
  EXPECT_LT(st.triangles, topo.triangleCount());
  EXPECT_EQ(st.nan_count, 0u);
  EXPECT_EQ(st.constraints[SIM_KIND_SHEAR], topo.kind_counts[SIM_KIND_SHEAR]);
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
  for (uint32_t k = 0; k < s.triangle_count; ++k) {
    glm::uvec2 e = topo.tri_edges[s.triangles[k].w];
    EXPECT_FALSE(s.torn[e.x] || s.torn[e.y]);
  }
}

TYPED_TEST(BothSolvers, NoNaNUnderWindAndCollision) {
  auto solver = this->make();
  Simulation sim(preset("crumple", {"cols=10", "rows=14", "wind=on", "pins=none"}), *solver);
  SimState s = run(sim, 120);
  SheetStats st = computeStats(s, sim.params().substepDt());
  EXPECT_EQ(st.nan_count, 0u);
  for (const glm::vec4& n : s.normal) EXPECT_NEAR(glm::length(glm::vec3(n)), 1.0f, 1e-4f);
}

TYPED_TEST(BothSolvers, ResetBringsTheSheetBack) {
  auto solver = this->make();
  Simulation sim(preset("tender", {"cols=8", "rows=12"}), *solver);
  sim.setScript(script("0 grab particle 95\n1 move 6 -5 6\n20 reset\n"));
  SimState torn = run(sim, 20);
  ASSERT_GT(computeStats(torn, 1.0f).torn, 0u);
  run(sim, SIM_RESET_FRAMES);
  EXPECT_FALSE(sim.resetting());
  SimState s = run(sim, 0);
  for (uint32_t i = 0; i < s.pos.size(); ++i) ASSERT_EQ(glm::vec3(s.pos[i]), glm::vec3(sim.topology().rest_pos[i]));
  EXPECT_EQ(computeStats(s, 1.0f).torn, 0u);
  EXPECT_EQ(s.triangle_count, sim.topology().triangleCount());
}

TYPED_TEST(BothSolvers, PauseFreezesTheState) {
  auto solver = this->make();
  Simulation sim(preset("tender", {"cols=8", "rows=12"}), *solver);
  sim.setScript(script("5 pause on\n10 pause off\n"));
  SimState a = run(sim, 6);
  SimState b = run(sim, 4);
  EXPECT_EQ(0, std::memcmp(a.pos.data(), b.pos.data(), a.pos.size() * sizeof(glm::vec4)));
}

TYPED_TEST(BothSolvers, PickNearestParticleWithinRadius) {
  auto solver = this->make();
  Simulation sim(preset("tender", {"cols=16", "rows=24"}), *solver);
  glm::vec3 target(sim.topology().rest_pos[200]);
  auto hit = solver->pick(target + glm::vec3(0.01f, 0.0f, 10.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.6f);
  EXPECT_EQ(hit.index, 200u);
  EXPECT_NEAR(hit.t, 10.0f, 1e-4f);
  // Equidistant particles: the smaller index wins.
  glm::vec3 mid = 0.5f * (glm::vec3(sim.topology().rest_pos[200]) + glm::vec3(sim.topology().rest_pos[201]));
  auto tie = solver->pick(mid + glm::vec3(0.0f, 0.0f, 10.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.6f);
  EXPECT_EQ(tie.index, 200u);
  auto miss = solver->pick(glm::vec3(50.0f, 0.0f, 10.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.6f);
  EXPECT_EQ(miss.index, SIM_NONE);
  EXPECT_TRUE(sim.grabRay(target + glm::vec3(0.0f, 0.0f, 5.0f), glm::vec3(0.0f, 0.0f, -1.0f)));
  EXPECT_EQ(sim.grabbed(), 200u);
  EXPECT_EQ(solver->particlePosition(200), target);
}
