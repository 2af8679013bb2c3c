// The numbering of a tick's passes (passes.h), which `tender diff` reports and stops at.
#include <gtest/gtest.h>

#include "core/passes.h"

using namespace tender;

namespace {

shaderio::SimUniforms uniforms(uint32_t substeps, uint32_t iterations, uint32_t colors, bool collision) {
  shaderio::SimUniforms u{};
  u.substeps = substeps;
  u.iterations = iterations;
  u.color_count = colors;
  u.flags = collision ? SIM_FLAG_COLLISION : 0u;
  return u;
}

/// The same with every stage's condition met: contact with the settle's sweeps, a stretch limit
/// that shortens edges first (nothing holds the sheet), hinges that crease.
shaderio::SimUniforms everyStage(uint32_t substeps, uint32_t iterations, uint32_t colors) {
  shaderio::SimUniforms u = uniforms(substeps, iterations, colors, true);
  u.grab_index = SIM_NONE;
  u.limit.reach = 1.0f;
  u.hinge.count = 4;
  u.crease.yield_angle = 0.2f;
  u.contact.radius = 0.1f;
  u.contact_check.sweeps = 2;
  return u;
}

} // namespace

TEST(Passes, OrderOfOneSubstep) {
  const shaderio::SimUniforms u = everyStage(3, 2, 5);
  ASSERT_EQ(passesPerTick(u), 3u * (1u + 1u + 1u + 10u + 10u + 1u + 1u + 1u + 1u + 1u));
  EXPECT_EQ(passAt(u, 0), (PassPoint{0, PassKind::contact}));
  EXPECT_EQ(passAt(u, 1), (PassPoint{0, PassKind::integrate}));
  EXPECT_EQ(passAt(u, 2), (PassPoint{0, PassKind::collide}));
  EXPECT_EQ(passAt(u, 3), (PassPoint{0, PassKind::project, 0, 0}));
  EXPECT_EQ(passAt(u, 9), (PassPoint{0, PassKind::project, 1, 1}));
  EXPECT_EQ(passAt(u, 12), (PassPoint{0, PassKind::project, 1, 4}));
  EXPECT_EQ(passAt(u, 13), (PassPoint{0, PassKind::shorten, 0, 0}));
  EXPECT_EQ(passAt(u, 22), (PassPoint{0, PassKind::shorten, 1, 4}));
  EXPECT_EQ(passAt(u, 23), (PassPoint{0, PassKind::limit}));
  EXPECT_EQ(passAt(u, 24), (PassPoint{0, PassKind::floor}));
  EXPECT_EQ(passAt(u, 25), (PassPoint{0, PassKind::settle}));
  EXPECT_EQ(passAt(u, 26), (PassPoint{0, PassKind::crease}));
  EXPECT_EQ(passAt(u, 27), (PassPoint{0, PassKind::tear}));
  EXPECT_EQ(passAt(u, 28), (PassPoint{1, PassKind::contact}));
  EXPECT_EQ(describePass(passAt(u, 37)), "substep 1, project (iteration 1, colour 1)");
  EXPECT_EQ(describePass(passAt(u, 49)), "substep 1, shorten (iteration 1, colour 3)");
  EXPECT_EQ(describePass(passAt(u, 51)), "substep 1, limit");
  EXPECT_EQ(describePass(passAt(u, 53)), "substep 1, settle");
  EXPECT_EQ(describePass(passAt(u, 54)), "substep 1, crease");
}

TEST(Passes, AStageIsNumberedOnlyWhileItsConditionHolds) {
  // Nothing on: the integration, the projection, the floor and the tear (the grab holds particle 0)
  shaderio::SimUniforms u = uniforms(2, 2, 3, false);
  EXPECT_EQ(passesPerTick(u), 2u * (1u + 6u + 1u + 1u));
  for (PassKind kind :
       {PassKind::contact, PassKind::air, PassKind::collide, PassKind::limit, PassKind::crease, PassKind::settle})
    EXPECT_FALSE(passIndex(u, PassPoint{0, kind})) << describePass(PassPoint{0, kind});
  EXPECT_FALSE(passIndex(u, PassPoint{0, PassKind::shorten, 0, 0}));
  // Each condition adds its stage's passes, the shorten stage's once per colour of each iteration
  const uint32_t base = passesPerTick(u);
  u.limit.reach = 1.0f;
  EXPECT_EQ(passesPerTick(u), base + 2u);
  EXPECT_EQ(passIndex(u, PassPoint{0, PassKind::limit}), 7u);
  u.grab_index = SIM_NONE;
  EXPECT_EQ(passesPerTick(u), base + 2u * (1u + 6u));
  u.flags |= SIM_FLAG_PINS; // pins hold the sheet: no shortening
  EXPECT_EQ(passesPerTick(u), base + 2u);
  u.contact.radius = 0.1f;
  EXPECT_EQ(passIndex(u, PassPoint{0, PassKind::contact}), 0u);
  EXPECT_FALSE(passIndex(u, PassPoint{0, PassKind::settle}));
  u.contact_check.sweeps = 4;
  EXPECT_EQ(passesPerTick(u), base + 2u * 3u);
  u.hinge.count = 3;
  EXPECT_EQ(passesPerTick(u), base + 2u * 3u);
  u.crease.yield_angle = 0.1f;
  EXPECT_EQ(passesPerTick(u), base + 2u * 4u);
  u.flags |= SIM_FLAG_AIR;
  EXPECT_EQ(passesPerTick(u), base + 2u * 5u);
  EXPECT_EQ(passIndex(u, PassPoint{0, PassKind::air}), 1u); // after contact's
  EXPECT_EQ(conditionsOf(u), SIM_WHEN_AIR | SIM_WHEN_CONTACT | SIM_WHEN_LIMIT | SIM_WHEN_CREASE | SIM_WHEN_SETTLE);
}

TEST(Passes, IndexIsTheInverseOfPassAt) {
  for (bool collision : {false, true})
    for (const shaderio::SimUniforms& u : {uniforms(1, 1, 1, collision), uniforms(8, 4, 9, collision)}) {
      const uint32_t n = passesPerTick(u);
      for (uint32_t k = 0; k < n; ++k) EXPECT_EQ(passIndex(u, passAt(u, k)), k);
    }
  shaderio::SimUniforms u = uniforms(2, 2, 3, false);
  EXPECT_EQ(passesPerTick(u), 2u * 9u);
  EXPECT_FALSE(passIndex(u, PassPoint{0, PassKind::collide}));
  EXPECT_FALSE(passIndex(u, PassPoint{2, PassKind::floor}));
  EXPECT_FALSE(passIndex(u, PassPoint{0, PassKind::project, 2, 0}));
  EXPECT_FALSE(passIndex(u, PassPoint{0, PassKind::project, 0, 3}));
  u = everyStage(2, 2, 3);
  EXPECT_FALSE(passIndex(u, PassPoint{0, PassKind::shorten, 2, 0}));
  for (uint32_t k = 0; k < passesPerTick(u); ++k) EXPECT_EQ(passIndex(u, passAt(u, k)), k);
  u.reset_active = 1;
  EXPECT_EQ(passesPerTick(u), 1u);
  EXPECT_EQ(passAt(u, 0).kind, PassKind::reset);
  EXPECT_EQ(describePass(passAt(u, 0)), "reset");
}

TEST(Passes, PlantedUlpParsesAndRefusesMalformedText) {
  std::string error;
  auto p = parsePlantedUlp("12:3:project.1.4:700", error);
  ASSERT_TRUE(p) << error;
  EXPECT_EQ(p->tick, 12u);
  EXPECT_EQ(p->pass, (PassPoint{3, PassKind::project, 1, 4}));
  EXPECT_EQ(p->particle, 700u);
  ASSERT_TRUE(parsePlantedUlp("0:0:floor:1", error));
  EXPECT_EQ(parsePlantedUlp("0:0:collide:1", error)->pass.kind, PassKind::collide);
  for (const char* bad : {"", "1:2:floor", "x:1:floor:2", "1:2:bogus:3", "1:2:project.1:3", "1:2:floor:-1",
                          "1:2:floor:3:4", "1:2:project.a.b:3"}) {
    error.clear();
    EXPECT_FALSE(parsePlantedUlp(bad, error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
}
