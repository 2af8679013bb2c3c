#pragma once
// The GPU tests' Vulkan context: lavapipe unless VK_DRIVER_FILES says otherwise, validation and
// synchronization validation always on; any validation message fails the test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <string>

#include "common/sim_helpers.h"
#include "cpu/cpu_solver.h"
#include "gpu/context.h"
#include "spirv_rules.h"

namespace tender::test {

/// The shared context of this test process (see testContext).
inline std::unique_ptr<gpu::VulkanContext>& sharedContext() {
  static std::unique_ptr<gpu::VulkanContext> ctx;
  return ctx;
}

/// Destroys the shared context when the tests end, while the driver is still loaded: left to the
/// static destructors, it would outlive the driver's own teardown at exit (NVIDIA's driver then
/// crashes the process after every test passed).
class ReleaseSharedContext : public ::testing::Environment {
public:
  void TearDown() override { sharedContext().reset(); }
};
inline ::testing::Environment* const kReleaseSharedContext =
    ::testing::AddGlobalTestEnvironment(new ReleaseSharedContext);

/// The shared context of this test process, or nullptr (and `why`) when there is no device.
inline gpu::VulkanContext* testContext(std::string& why) {
  std::unique_ptr<gpu::VulkanContext>& ctx = sharedContext();
  static std::string error;
  static bool tried = false;
  if (!tried) {
    tried = true;
    gpu::preferLavapipeForTests();
    gpu::ContextOptions o;
    o.validation = true;
    o.sync_validation = true;
    auto r = gpu::VulkanContext::create(o);
    if (r)
      ctx = std::move(r.value());
    else
      error = r.error();
  }
  why = error;
  return ctx.get();
}

/// True under CI=true, where a missing Vulkan device is a failure rather than a skip.
inline bool inCi() {
  const char* ci = std::getenv("CI");
  return ci && std::strcmp(ci, "true") == 0;
}

/// Largest |a - b| over the xyz of two position arrays (infinite when their sizes differ).
inline float maxAbsDiff(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
  if (a.size() != b.size()) return INFINITY;
  float m = 0.0f;
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) m = std::max(m, std::abs(a[i][k] - b[i][k]));
  return m;
}

/// Parity: two states hold the same bits in their positions, previous positions and hinge states
/// (rest angles, yields, multipliers), and the same number of particles (an empty or short
/// read-back fails). On failure: the first particle that differs and the largest difference.
inline ::testing::AssertionResult sameState(const SimState& a, const SimState& b) {
  if (a.pos.empty() || a.pos.size() != b.pos.size() || a.prev.size() != b.prev.size())
    return ::testing::AssertionFailure() << "the states differ in size: " << a.pos.size() << " and " << b.pos.size()
                                         << " particles";
  if (a.hinges.size() != b.hinges.size() || !sameBytes(a.hinges, b.hinges)) {
    size_t first = 0;
    while (first < std::min(a.hinges.size(), b.hinges.size()) &&
           std::memcmp(&a.hinges[first], &b.hinges[first], sizeof(glm::vec4)) == 0)
      ++first;
    return ::testing::AssertionFailure() << "the hinge states part at hinge " << first << " of " << a.hinges.size();
  }
  if (sameBytes(a.pos, b.pos) && sameBytes(a.prev, b.prev)) return ::testing::AssertionSuccess();
  size_t first = 0;
  while (first < a.pos.size() && std::memcmp(&a.pos[first], &b.pos[first], sizeof(glm::vec4)) == 0 &&
         std::memcmp(&a.prev[first], &b.prev[first], sizeof(glm::vec4)) == 0)
    ++first;
  return ::testing::AssertionFailure() << "the states part at particle " << first
                                       << "; max |dx| = " << maxAbsDiff(a.pos, b.pos);
}

/// Base of every GPU test: gets the context (skip or, under CI, fail without one) and fails the
/// test on any validation message it caused.
class GpuTest : public ::testing::Test {
protected:
  void SetUp() override {
    std::string why;
    ctx_ = testContext(why);
    if (!ctx_) {
      // Every GPU test runs under validation: a missing layer fails everywhere (tools/setup
      // installs it), while a machine without any Vulkan device skips outside CI.
      if (why.find("VK_LAYER_KHRONOS_validation") != std::string::npos) FAIL() << why;
      if (inCi()) FAIL() << "no Vulkan device under CI=true: " << why;
      GTEST_SKIP() << "no Vulkan device (" << why << "); GPU tests skipped";
    }
    messages_ = ctx_->validationMessages();
  }
  void TearDown() override {
    if (ctx_) {
      EXPECT_EQ(ctx_->validationMessages(), messages_) << "validation messages during the test";
    }
  }

public:
  /// The shared context (set up unless the test was skipped).
  gpu::VulkanContext& ctx() { return *ctx_; }

protected:
  gpu::VulkanContext* ctx_ = nullptr;
  uint32_t messages_ = 0;
};

} // namespace tender::test
