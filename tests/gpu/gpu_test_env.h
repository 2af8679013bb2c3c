#pragma once
// The GPU tests' Vulkan context: lavapipe unless VK_DRIVER_FILES says otherwise, validation and
// synchronization validation always on; any validation message fails the test.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <string>

#include "core/params.h"
#include "core/script.h"
#include "core/simulation.h"
#include "gpu/context.h"

namespace tender::test {

/// The shared context of this test process, or nullptr (and `why`) when there is no device.
inline gpu::VulkanContext* testContext(std::string& why) {
  static std::unique_ptr<gpu::VulkanContext> ctx;
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

/// Parameters of a preset with overrides (which must be valid).
inline SimParams preset(const char* name, std::initializer_list<const char*> sets = {}) {
  SimParams p = *presetParams(name);
  for (const char* s : sets) {
    auto err = applyOverride(p, s);
    EXPECT_FALSE(err) << *err;
  }
  auto err = validate(p);
  EXPECT_FALSE(err) << *err;
  return p;
}

/// Parses an input script.
inline InputScript script(const char* text) {
  std::string err;
  auto s = parseScript(text, err);
  EXPECT_TRUE(s) << err;
  return s ? *s : InputScript{};
}

/// Ticks the simulation and reads the state back.
inline SimState run(Simulation& sim, int ticks) {
  for (int t = 0; t < ticks; ++t) sim.tick();
  SimState s;
  sim.solver().computeNormals();
  sim.solver().readback(s);
  return s;
}

/// Largest |a - b| over the xyz of two position arrays.
inline float maxAbsDiff(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
  float m = 0.0f;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    for (int k = 0; k < 3; ++k) m = std::max(m, std::abs(a[i][k] - b[i][k]));
  return m;
}

/// Base of every GPU test: gets the context (skip or, under CI, fail without one) and fails the
/// test on any validation message it caused.
class GpuTest : public ::testing::Test {
protected:
  void SetUp() override {
    std::string why;
    ctx_ = testContext(why);
    if (!ctx_) {
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
  gpu::VulkanContext& ctx() { return *ctx_; }

  gpu::VulkanContext* ctx_ = nullptr;
  uint32_t messages_ = 0;
};

} // namespace tender::test
