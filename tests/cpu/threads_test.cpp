// The CPU solver gives bitwise identical results on any number of threads, and with or without
// its collision candidate lists.
#include <gtest/gtest.h>

#include <algorithm>
#include <thread>

#include "cpu/cpu_runs.h"

using namespace tender;

namespace {

using test::expectIdentical;
using test::tornCount;

// The cloth runs have no contact; contact's threads: the crumple runs
SimState run(const SimParams& p, const std::string& script, int ticks, CpuOptions options) {
  return test::runCpu(p, script, ticks, options);
}
using test::cloth;
using test::preset;

// min_chunk = 1 splits every loop, however small, so the small sheets exercise every parallel path.
constexpr CpuOptions kOne{1, 1}, kTwo{2, 1}, kThree{3, 1};
// Without collision candidate lists: the hash and the 27-cell search in every substep.
constexpr CpuOptions kOneNoLists{1, 1, false};

} // namespace

TEST(CpuThreads, HangingSheetIsIdenticalOnOneAndTwoThreads) {
  SimState one = run(cloth(), "", 20, kOne);
  SimState two = run(cloth(), "", 20, kTwo);
  expectIdentical(one, two);
}

TEST(CpuThreads, TearingYankIsIdenticalOnOneAndTwoThreads) {
  // (it tears in its second tick; the last ticks run let go)
  const std::string yank = "0 grab particle 1535\n1 move 4 -4 6\n12 release\n";
  SimState two = run(cloth(), yank, 20, kTwo);
  EXPECT_GT(tornCount(two), 0u); // the run really tears and compacts
  EXPECT_LT(two.triangle_count, 2914u);
  if (kComparesThreadCounts) expectIdentical(run(cloth(), yank, 20, kOne), two);
}

TEST(CpuThreads, CrumpleTossAndAwkwardSizeAreIdentical) {
  const std::string toss = "0 grab particle 100\n1 move 1 2 3\n10 release\n";
  expectIdentical(run(crumpleSheet({"cols=13", "rows=19"}), toss, 40, kOne),
                  run(crumpleSheet({"cols=13", "rows=19"}), toss, 40, kThree));
}

TEST(CpuThreads, TunedChunkingIsIdenticalOnALargerSheet) {
  // Default chunk sizes: the loops of a 64 x 128 sheet are split the way real runs split them (its
  // 8192 particles are two shares of kGrainParticles, its colours several of kGrainConstraints).
  const std::string yank = "0 grab particle 8191\n1 move 6 -4 8\n12 release\n";
  SimState two = run(cloth({"cols=64", "rows=128"}), yank, 20, CpuOptions{.threads = 2, .min_chunk = 0});
  if (kComparesThreadCounts)
    expectIdentical(run(cloth({"cols=64", "rows=128"}), yank, 20, CpuOptions{.threads = 1, .min_chunk = 0}), two);
}

TEST(CpuThreads, FullAdjacencyAndFourThreadsAreIdentical) {
  // Bend and triangle bend together: 16 neighbours per inner particle, the most the collision
  // pass's adjacency test holds in registers; four workers split every loop and phase.
  const std::string yank = "0 grab particle 1535\n1 move 4 -4 6\n12 release\n";
  SimState four = run(cloth({"tri_bend=on"}), yank, 20, CpuOptions{.threads = 4, .min_chunk = 1});
  EXPECT_GT(tornCount(four), 0u);
  if (kComparesThreadCounts) expectIdentical(run(cloth({"tri_bend=on"}), yank, 20, kOne), four);
}

TEST(CpuThreads, ResetAndNoCollisionAreIdentical) {
  const std::string script = "0 grab particle 1535\n1 move 4 -4 6\n20 reset\n";
  expectIdentical(run(cloth({"collision=off"}), script, 40, kOne), run(cloth({"collision=off"}), script, 40, kTwo));
}

TEST(CpuThreads, ZeroMeansOnePerHardwareThread) {
  const uint32_t cores = std::clamp(std::thread::hardware_concurrency(), 1u, 64u);
  EXPECT_EQ(CpuSolver(CpuOptions{.threads = 0}).threadCount(), cores);
  EXPECT_EQ(CpuSolver(CpuOptions{.threads = 3}).threadCount(), 3u);
}

TEST(CpuThreads, MemoryIsReported) {
  SimParams p = clothWithContact();
  CpuSolver solver;
  Simulation sim(p, solver);
  // At least pos, prev, rest, normal (16 bytes each) per particle, and the constraints.
  EXPECT_GE(solver.memoryBytes(), 1536u * 64u + 8818u * 16u);
}

TEST(CpuCandidateLists, ListsAreUsedAndChangeNothing) {
  // A sheet hanging in the wind: most substeps sum from the lists.
  const SimParams p = cloth({"wind=on"});
  CpuSolver solver(kTwo);
  Simulation sim(p, solver);
  uint32_t on_lists = 0;
  for (int t = 0; t < 60; ++t) {
    sim.tick();
    on_lists += solver.candidateState().x == 1u && solver.candidateState().y >= p.substeps ? 1u : 0u;
  }
  EXPECT_GT(on_lists, 30u);
  if (!kComparesThreadCounts) return; // ThreadSanitizer judges the two threads' run
  solver.computeNormals();
  SimState with;
  solver.readback(with);
  expectIdentical(with, run(cloth({"wind=on"}), "", 60, kOneNoLists));
}

TEST(CpuCandidateLists, DragTossAndCrowdsAreIdenticalWithoutLists) {
  // A drag that tears (lists outgrown, then waiting), a crumple toss, a radius of 1.6 spacings
  // (lists of several candidates each) and one of 2.5 spacings (lists overflow).
  const std::string drag = "0 grab particle 1535\n1 move 1 2 1\n10 move 2 0 2\n20 move 4 -4 6\n40 release\n";
  SimState a = run(cloth({"wind=on"}), drag, 80, kTwo);
  EXPECT_GT(tornCount(a), 0u);
  expectIdentical(a, run(cloth({"wind=on"}), drag, 80, kOneNoLists));
  const std::string toss = "0 grab particle 100\n1 move 1 2 3\n10 release\n";
  expectIdentical(run(crumpleSheet({"cols=13", "rows=19"}), toss, 40, kThree),
                  run(crumpleSheet({"cols=13", "rows=19"}), toss, 40, kOneNoLists));
  expectIdentical(run(cloth({"collision_factor=1.6", "wind=on"}), drag, 40, kTwo),
                  run(cloth({"collision_factor=1.6", "wind=on"}), drag, 40, kOneNoLists));
  expectIdentical(run(cloth({"cols=16", "rows=20", "collision_factor=2.5", "cell_size=0.9"}), "", 20, kTwo),
                  run(cloth({"cols=16", "rows=20", "collision_factor=2.5", "cell_size=0.9"}), "", 20, kOneNoLists));
}
