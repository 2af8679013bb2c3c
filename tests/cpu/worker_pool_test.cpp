// The worker pool runs every chunk once, keeps the phases of a job in order, and never hangs,
// also with more workers than cores.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <thread>
#include <vector>

#include "cpu/worker_pool.h"

using namespace tender;

TEST(WorkerPool, RunsEveryChunkOnce) {
  for (uint32_t threads : {1u, 2u, 3u, 8u}) {
    WorkerPool pool(threads);
    for (uint32_t chunks : {0u, 1u, 2u, 5u, WorkerPool::kMaxChunks}) {
      std::vector<std::atomic<uint32_t>> calls(chunks);
      for (int job = 0; job < 50; ++job) pool.run(chunks, [&](uint32_t c) { calls[c].fetch_add(1); });
      for (uint32_t c = 0; c < chunks; ++c) EXPECT_EQ(calls[c].load(), 50u) << threads << " threads, chunk " << c;
    }
  }
}

TEST(WorkerPool, PhasesRunInOrder) {
  // Chunk c of phase p writes step[p % 2][c] = p + 1 and reads what every chunk wrote in phase
  // p - 1 (plain data: the phase boundary orders it).
  for (uint32_t threads : {2u, 3u, 8u}) {
    WorkerPool pool(threads);
    constexpr uint32_t kPhases = 40, kChunks = 6;
    for (int job = 0; job < 20; ++job) {
      std::vector<uint32_t> step[2] = {std::vector<uint32_t>(kChunks, 0), std::vector<uint32_t>(kChunks, 0)};
      std::atomic<uint32_t> wrong{0};
      pool.runPhases(kPhases, kChunks, [&](uint32_t p, uint32_t c) {
        if (p > 0)
          for (uint32_t other = 0; other < kChunks; ++other)
            if (step[(p - 1) % 2][other] != p) wrong.fetch_add(1);
        step[p % 2][c] = p + 1;
      });
      EXPECT_EQ(wrong.load(), 0u) << threads << " threads";
      for (uint32_t c = 0; c < kChunks; ++c) EXPECT_EQ(step[(kPhases - 1) % 2][c], kPhases);
    }
  }
}

TEST(WorkerPool, ParallelForCoversTheRangeInWholeGroups) {
  WorkerPool pool(3);
  for (uint32_t n : {0u, 1u, 7u, 100u, 1001u}) {
    std::vector<std::atomic<uint32_t>> seen(n);
    pool.parallelFor(
        n, 1,
        [&](uint32_t begin, uint32_t end) {
          EXPECT_EQ(begin % 4, 0u);
          for (uint32_t i = begin; i < end; ++i) seen[i].fetch_add(1);
        },
        4);
    for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(seen[i].load(), 1u) << "n " << n << ", i " << i;
  }
}

TEST(WorkerPool, ManyMoreWorkersThanCoresFinish) {
  // Oversubscribed (as under ctest -j): helpers the OS has not scheduled must not stall the jobs.
  WorkerPool pool(4 * std::max(1u, std::thread::hardware_concurrency()));
  std::atomic<uint64_t> sum{0};
  for (int job = 0; job < 2000; ++job)
    pool.runPhases(3, WorkerPool::kMaxChunks, [&](uint32_t p, uint32_t c) { sum.fetch_add(p * 100 + c); });
  uint64_t expected = 0;
  for (uint32_t p = 0; p < 3; ++p)
    for (uint32_t c = 0; c < WorkerPool::kMaxChunks; ++c) expected += p * 100 + c;
  EXPECT_EQ(sum.load(), 2000 * expected);
}

TEST(WorkerPool, JobsOfChangingShapeRunExactlyOnce) {
  // Back-to-back jobs whose phase and chunk counts change from one to the next (as the solver's
  // loops do): a helper still looking at the finished job must never claim a chunk with the new
  // job's counts. A lost or doubled chunk shows in the sums; a hang fails through the watchdog.
  std::atomic<bool> finished{false};
  std::thread watchdog([&] {
    for (int i = 0; i < 600 && !finished.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!finished.load()) {
      ADD_FAILURE() << "the pool hung";
      std::_Exit(1);
    }
  });
  for (uint32_t threads : {2u, 3u}) {
    WorkerPool pool(threads);
    for (uint32_t job = 0; job < 100000; ++job) {
      const uint32_t phases = 1 + job % 3, chunks = 2 + (job * 7) % 5;
      std::atomic<uint32_t> calls{0};
      pool.runPhases(phases, chunks, [&](uint32_t, uint32_t) { calls.fetch_add(1); });
      ASSERT_EQ(calls.load(), phases * chunks) << threads << " threads, job " << job;
    }
  }
  finished.store(true);
  watchdog.join();
}
