// tender-bench's dispatch cost (bench/dispatch_cost.h) under the validation layers with
// synchronization validation: chains of empty dispatches and barriers, timed, with no message.
#include <gtest/gtest.h>

#include <algorithm>

#include "dispatch_cost.h"
#include "gpu_test_env.h"

using namespace tender;

using DispatchCostTest = test::GpuTest;

TEST_F(DispatchCostTest, EmptyDispatchChainsAreTimedCleanly) {
  std::string error;
  auto cost = bench::measureDispatchCost(ctx(), error, 100, 3);
  ASSERT_TRUE(cost.has_value()) << error;
  EXPECT_EQ(cost->chain, 100u);
  EXPECT_EQ(cost->repetitions, 3u);
  ASSERT_EQ(cost->samples_us.size(), 3u);
  for (double us : cost->samples_us) EXPECT_GT(us, 0.0);
  std::vector<double> sorted = cost->samples_us;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(cost->us, sorted[1]); // the median
  EXPECT_NE(cost->method.find(ctx().properties().deviceName), std::string::npos) << cost->method;
}

TEST_F(DispatchCostTest, AnEmptyChainIsRefused) {
  std::string error;
  EXPECT_FALSE(bench::measureDispatchCost(ctx(), error, 0, 3).has_value());
  EXPECT_FALSE(error.empty());
}
