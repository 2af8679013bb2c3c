// The scene view of a preset: the paper preset, 30 cm long in SI units, is framed at its own size,
// its view following it down.
#include <gtest/gtest.h>

#include <cstdio>

#include "common/sim_helpers.h"
#include "core/params.h"
#include "core/sheet.h"
#include "cpu/cpu_solver.h"
#include "render/renderer.h"

namespace tender::render {
namespace {

// Where the sheet's particles land in a 16:9 view: the largest of the box's width and height as a
// part of the view's (1: the whole view), and whether every particle is inside it.
struct InView {
  float share = 0.0f;
  bool inside = true;
};
InView sheetInView(const SceneView& v, const std::vector<glm::vec4>& pos) {
  glm::vec2 lo(1e9f), hi(-1e9f);
  InView in;
  for (const glm::vec4& x : pos) {
    auto at = v.camera.viewPoint(glm::vec3(x), 16.0f / 9.0f);
    if (!at) {
      in.inside = false;
      continue;
    }
    in.inside = in.inside && std::abs(at->x) <= 1.0f && std::abs(at->y) <= 1.0f;
    lo = glm::min(lo, *at);
    hi = glm::max(hi, *at);
  }
  in.share = 0.5f * std::max(hi.x - lo.x, hi.y - lo.y);
  return in;
}

TEST(SceneView, ThePaperPresetIsFramedAtItsOwnScale) {
  const SimParams p = *presetParams("paper");
  const SceneView v = defaultSceneView(p);
  EXPECT_FLOAT_EQ(v.scale, p.view_scale);
  // The zoom range and the ground scale with the scene
  EXPECT_FLOAT_EQ(v.camera.minRadius(), OrbitCamera::kMinRadius * p.view_scale);
  EXPECT_GE(v.camera.radius(), v.camera.minRadius());
  EXPECT_LE(v.camera.radius(), v.camera.maxRadius());
  EXPECT_GT(v.sheet_share, 0.0f); // a framed sheet, its centre followed
  EXPECT_GE(v.ground, 0.7f);      // the ground reaches where the sheet lands
}

// The 30 cm receipt, let go 1 m above the floor, fills about a third of the view through its fall
// and its landing (a fixed view of the fall showed it landed as 55 x 70 pixels of 1280 x 720), as
// `tender render` and the demo draw it: the target on the centre of its sample points.
TEST(SceneView, ThePaperReceiptFillsAThirdOfTheViewAsItFallsAndLands) {
  const SimParams p = *presetParams("paper");
  CpuSolver solver;
  Simulation sim(p, solver);
  const std::vector<uint32_t> samples = sheetSamples(sim.topology());
  ASSERT_EQ(samples.size(), 9u);
  float first_y = 0.0f;
  for (int tick = 0; tick <= 300; tick += 50) {
    const SimState s = test::run(sim, tick == 0 ? 0 : 50);
    SceneView v = defaultSceneView(p);
    followSheet(v, solver.particlePositions(samples));
    const InView in = sheetInView(v, s.pos);
    std::printf("tick %d: the receipt spans %.2f of the view%s\n", tick, double(in.share),
                in.inside ? "" : ", not all in it");
    EXPECT_TRUE(in.inside) << "tick " << tick;
    EXPECT_GE(in.share, 0.2f) << "tick " << tick;
    EXPECT_LE(in.share, 0.6f) << "tick " << tick;
    if (tick == 0) first_y = v.camera.target().y;
    if (tick == 300) {
      EXPECT_LT(v.camera.target().y, first_y - 0.5f) << "the target followed it down";
    }
  }
  EXPECT_NEAR(sim.solver().particlePositions({samples[4]})[0].y, p.floor_y, 0.05f) << "landed by tick 300";
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
