// The scene view of a preset: the paper preset, 30 cm long in SI units, is framed at its own size.
#include <gtest/gtest.h>

#include "core/params.h"
#include "core/sheet.h"
#include "render/renderer.h"

namespace tender::render {
namespace {

TEST(SceneView, ThePaperPresetIsFramedAtItsOwnScale) {
  const SimParams p = *presetParams("paper");
  const SceneView v = defaultSceneView(p);
  EXPECT_FLOAT_EQ(v.scale, p.view_scale);
  // The zoom range and the ground scale with the scene
  EXPECT_FLOAT_EQ(v.camera.minRadius(), OrbitCamera::kMinRadius * p.view_scale);
  EXPECT_LE(v.camera.radius(), v.camera.maxRadius());
  // The whole sheet at its start, and the floor below it out to where it glides, are in view,
  // and the sheet fills a fair part of it
  const SheetTopology topo = buildSheet(p);
  glm::vec2 lo(1e9f), hi(-1e9f);
  for (const glm::vec4& r : topo.rest_pos) {
    auto at = v.camera.viewPoint(glm::vec3(r), 16.0f / 9.0f);
    ASSERT_TRUE(at);
    EXPECT_LE(std::abs(at->x), 1.0f);
    EXPECT_LE(std::abs(at->y), 1.0f);
    lo = glm::min(lo, *at);
    hi = glm::max(hi, *at);
  }
  EXPECT_GT(std::max(hi.x - lo.x, hi.y - lo.y), 0.1f);
  for (glm::vec3 floor : {glm::vec3(0.0f, p.floor_y, 0.0f), glm::vec3(0.0f, p.floor_y, -0.7f)}) {
    auto at = v.camera.viewPoint(floor, 16.0f / 9.0f);
    ASSERT_TRUE(at);
    EXPECT_LE(std::abs(at->x), 1.0f);
    EXPECT_LE(std::abs(at->y), 1.0f);
  }
  EXPECT_GE(v.ground, 0.7f); // the ground reaches where the sheet lands
}

TEST(SceneView, TheTenderPresetKeepsTheSpecView) {
  const SceneView v = defaultSceneView(*presetParams("tender"));
  EXPECT_FLOAT_EQ(v.scale, 1.0f);
  EXPECT_FLOAT_EQ(v.ground, 5.0f);
  const glm::vec3 eye = v.camera.eye();
  EXPECT_NEAR(eye.x, 6.0f, 1e-4f);
  EXPECT_NEAR(eye.y, 4.0f, 1e-4f);
  EXPECT_NEAR(eye.z, 10.0f, 1e-4f);
}

} // namespace
} // namespace tender::render
