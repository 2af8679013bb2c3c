// The behaviour every solver shares (tests/common/solver_cases.h) on both GPU paths: the fused
// small-sheet tick and the per-colour passes, built as every program builds them.
#include "backend/backend.h"
#include "common/solver_cases.h"
#include "gpu_test_env.h"

using namespace tender;
using namespace tender::test;

namespace {

template <const char* kBackend>
struct GpuBackend {
  static constexpr const char* kName = kBackend;
  using Fixture = GpuTest;
  static std::unique_ptr<Solver> make(GpuTest& f) {
    BackendOptions o;
    o.backend = kBackend;
    o.context = &f.ctx();
    Backend b;
    auto err = createBackend(o, b);
    EXPECT_FALSE(err) << *err;
    return std::move(b.solver);
  }
};

constexpr char kFused[] = "gpu", kPerColor[] = "gpu-percolor";

} // namespace

namespace tender::test {
using GpuBackends = ::testing::Types<GpuBackend<kFused>, GpuBackend<kPerColor>>;
INSTANTIATE_TYPED_TEST_SUITE_P(Gpu, SolverCase, GpuBackends, BackendName);
} // namespace tender::test
