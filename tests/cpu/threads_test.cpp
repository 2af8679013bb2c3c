// The CPU solver gives bitwise identical results on any number of threads, and with or without
// its collision candidate lists.
#include <gtest/gtest.h>

#include <cstring>

#include "core/simulation.h"
#include "cpu/cpu_solver.h"

using namespace tender;

namespace {

// Runs `ticks` ticks of a preset (with overrides and a script) and returns the final state.
SimState run(const std::string& preset, std::vector<std::string> sets, const std::string& script, uint32_t ticks,
             CpuOptions options) {
  SimParams p = *presetParams(preset);
  for (auto& s : sets) EXPECT_FALSE(applyOverride(p, s).has_value()) << s;
  EXPECT_FALSE(validate(p).has_value());
  CpuSolver solver(options);
  Simulation sim(p, solver);
  if (!script.empty()) {
    std::string error;
    auto parsed = parseScript(script, error);
    EXPECT_TRUE(parsed.has_value()) << error;
    sim.setScript(*parsed);
  }
  for (uint32_t t = 0; t < ticks; ++t) sim.tick();
  solver.computeNormals();
  SimState s;
  solver.readback(s);
  return s;
}

template <typename T>
bool sameBytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

void expectIdentical(const SimState& a, const SimState& b) {
  EXPECT_TRUE(sameBytes(a.pos, b.pos));
  EXPECT_TRUE(sameBytes(a.prev, b.prev));
  EXPECT_TRUE(sameBytes(a.normal, b.normal));
  EXPECT_TRUE(sameBytes(a.constraints, b.constraints));
  EXPECT_TRUE(sameBytes(a.colors, b.colors));
  EXPECT_TRUE(sameBytes(a.torn, b.torn));
  EXPECT_TRUE(sameBytes(a.triangles, b.triangles));
  EXPECT_EQ(a.triangle_count, b.triangle_count);
}

uint32_t tornCount(const SimState& s) {
  uint32_t n = 0;
  for (uint32_t t : s.torn) n += t ? 1u : 0u;
  return n;
}

// min_chunk = 1 splits every loop, however small, so the small sheets exercise every parallel path.
constexpr CpuOptions kOne{1, 1}, kTwo{2, 1}, kThree{3, 1};
// Without collision candidate lists: the hash and the 27-cell search in every substep.
constexpr CpuOptions kOneNoLists{1, 1, false};

} // namespace

TEST(CpuThreads, HangingSheetIsIdenticalOnOneAndTwoThreads) {
  SimState one = run("tender", {}, "", 60, kOne);
  SimState two = run("tender", {}, "", 60, kTwo);
  expectIdentical(one, two);
}

TEST(CpuThreads, TearingYankIsIdenticalOnOneAndTwoThreads) {
  const std::string yank = "0 grab particle 1535\n1 move 4 -4 6\n40 release\n";
  SimState one = run("tender", {}, yank, 80, kOne);
  SimState two = run("tender", {}, yank, 80, kTwo);
  EXPECT_GT(tornCount(one), 0u); // the run really tears and compacts
  EXPECT_LT(one.triangle_count, 2914u);
  expectIdentical(one, two);
}

TEST(CpuThreads, CrumpleTossAndAwkwardSizeAreIdentical) {
  const std::string toss = "0 grab particle 100\n1 move 1 2 3\n10 release\n";
  expectIdentical(run("crumple", {"cols=37", "rows=53"}, toss, 40, kOne),
                  run("crumple", {"cols=37", "rows=53"}, toss, 40, kThree));
}

TEST(CpuThreads, TunedChunkingIsIdenticalOnALargerSheet) {
  // Default chunk sizes: the loops of a 96 x 144 sheet are split the way real runs split them.
  const std::string yank = "0 grab particle 13823\n1 move 6 -4 8\n20 release\n";
  SimState one = run("tender", {"cols=96", "rows=144"}, yank, 24, CpuOptions{1, 0});
  SimState two = run("tender", {"cols=96", "rows=144"}, yank, 24, CpuOptions{2, 0});
  expectIdentical(one, two);
}

TEST(CpuThreads, FullAdjacencyAndFourThreadsAreIdentical) {
  // Bend and triangle bend together: 16 neighbours per inner particle, the most the collision
  // pass's adjacency test holds in registers; four workers split every loop and phase.
  const std::string yank = "0 grab particle 1535\n1 move 4 -4 6\n30 release\n";
  SimState one = run("tender", {"tri_bend=on"}, yank, 50, kOne);
  EXPECT_GT(tornCount(one), 0u);
  expectIdentical(one, run("tender", {"tri_bend=on"}, yank, 50, CpuOptions{4, 1}));
}

TEST(CpuThreads, ResetAndNoCollisionAreIdentical) {
  const std::string script = "0 grab particle 1535\n1 move 4 -4 6\n20 reset\n";
  expectIdentical(run("tender", {"collision=off"}, script, 40, kOne),
                  run("tender", {"collision=off"}, script, 40, kTwo));
}

TEST(CpuThreads, ZeroMeansOnePerCore) {
  CpuSolver solver(CpuOptions{0, 0});
  EXPECT_GE(solver.threadCount(), 1u);
  EXPECT_EQ(CpuSolver(CpuOptions{2, 0}).threadCount(), 2u);
}

TEST(CpuThreads, MemoryIsReported) {
  SimParams p = *presetParams("tender");
  CpuSolver solver;
  Simulation sim(p, solver);
  // At least pos, prev, rest, normal (16 bytes each) per particle, and the constraints.
  EXPECT_GE(solver.memoryBytes(), 1536u * 64u + 8818u * 16u);
}

TEST(CpuCollisionLists, ListsAreUsedAndChangeNothing) {
  // A sheet hanging in the wind: most substeps sum from the lists.
  SimParams p = *presetParams("tender");
  ASSERT_FALSE(applyOverride(p, "wind=on").has_value());
  CpuSolver solver(kTwo);
  Simulation sim(p, solver);
  uint32_t on_lists = 0;
  for (int t = 0; t < 60; ++t) {
    sim.tick();
    on_lists += solver.listState().x == 1u && solver.listState().y >= p.substeps ? 1u : 0u;
  }
  EXPECT_GT(on_lists, 30u);
  solver.computeNormals();
  SimState with;
  solver.readback(with);
  expectIdentical(with, run("tender", {"wind=on"}, "", 60, kOneNoLists));
}

TEST(CpuCollisionLists, DragTossAndCrowdsAreIdenticalWithoutLists) {
  // A drag that tears (lists outgrown, then waiting), a crumple toss, a radius of 1.6 spacings
  // (lists of several candidates each) and one of 2.5 spacings (lists overflow).
  const std::string drag = "0 grab particle 1535\n1 move 1 2 1\n10 move 2 0 2\n20 move 4 -4 6\n40 release\n";
  SimState a = run("tender", {"wind=on"}, drag, 80, kTwo);
  EXPECT_GT(tornCount(a), 0u);
  expectIdentical(a, run("tender", {"wind=on"}, drag, 80, kOneNoLists));
  const std::string toss = "0 grab particle 100\n1 move 1 2 3\n10 release\n";
  expectIdentical(run("crumple", {"cols=37", "rows=53"}, toss, 40, kThree),
                  run("crumple", {"cols=37", "rows=53"}, toss, 40, kOneNoLists));
  expectIdentical(run("tender", {"collision_factor=1.6", "wind=on"}, drag, 40, kTwo),
                  run("tender", {"collision_factor=1.6", "wind=on"}, drag, 40, kOneNoLists));
  expectIdentical(run("tender", {"cols=16", "rows=20", "collision_factor=2.5", "cell_size=0.9"}, "", 20, kTwo),
                  run("tender", {"cols=16", "rows=20", "collision_factor=2.5", "cell_size=0.9"}, "", 20, kOneNoLists));
}
