// The CPU reference flushes denormals (FTZ and DAZ), as the shaders do on every device: on every
// worker of its pool and on the calling thread; a pool not asked to keeps them.
#include <gtest/gtest.h>

#include <bit>
#include <vector>

#include "core/denormal_mode.h"
#include "cpu/cpu_solver.h"
#include "cpu/worker_pool.h"

using namespace tender;

namespace {

// a * b on every chunk of a job over `pool` (each chunk on whichever worker claims it)
std::vector<uint32_t> products(WorkerPool& pool, float a, float b) {
  std::vector<uint32_t> out(32);
  pool.run(32, [&](uint32_t chunk) {
    volatile float x = a, y = b;
    out[chunk] = std::bit_cast<uint32_t>(float(x * y));
  });
  return out;
}

} // namespace

TEST(DenormalMode, ThePoolFlushesOnEveryWorkerOnlyWhenAsked) {
  const float tiny = 1e-20f; // its square is a denormal
  WorkerPool keep(4), flush(4, true);
  for (uint32_t r : products(keep, tiny, tiny)) EXPECT_NE(r & 0x7FFFFFFFu, 0u);
  for (uint32_t r : products(flush, tiny, tiny)) EXPECT_EQ(r, 0u);
  // Denormal inputs read as zero (DAZ), and the calling thread's mode is restored after the job
  for (uint32_t r : products(flush, std::bit_cast<float>(0x00400000u), 4.0f)) EXPECT_EQ(r, 0u);
  volatile float x = tiny;
  EXPECT_NE(std::bit_cast<uint32_t>(float(x * x)), 0u);
}

TEST(DenormalMode, TheSolverSaysHowItTreatsDenormals) {
  EXPECT_EQ(CpuSolver().arithmetic().denormals, "flush to zero (FTZ, DAZ)");
}
