// The orbit camera: the spec's start view, clamps, rays, the grab plane and the follow of a tossed sheet.
#include <gtest/gtest.h>

#include <algorithm>
#include <span>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "render/camera.h"

using tender::render::OrbitCamera;

namespace {

void expectNear(glm::vec3 a, glm::vec3 b, float eps = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

} // namespace

TEST(Camera, StartsAtTheSpecView) {
  OrbitCamera c;
  expectNear(c.eye(), {6.0f, 4.0f, 10.0f});
  expectNear(c.target(), {0.0f, 1.0f, 0.0f});
  EXPECT_FLOAT_EQ(OrbitCamera::kFovDegrees, 50.0f);
}

TEST(Camera, PhiStaysInRange) {
  OrbitCamera c;
  c.orbit(0.0f, 1e6f);
  EXPECT_FLOAT_EQ(c.phi(), 0.1f);
  c.orbit(0.0f, -1e6f);
  EXPECT_FLOAT_EQ(c.phi(), 3.14159265f - 0.1f);
  c.orbit(123.0f, 0.0f); // theta is free
  EXPECT_FLOAT_EQ(c.phi(), 3.14159265f - 0.1f);
}

TEST(Camera, OrbitKeepsDistanceAndTarget) {
  OrbitCamera c;
  float r = c.radius();
  c.orbit(200.0f, -50.0f);
  EXPECT_NEAR(glm::length(c.eye() - c.target()), r, 1e-4f);
  expectNear(c.target(), {0.0f, 1.0f, 0.0f});
}

TEST(Camera, ZoomStaysInRange) {
  OrbitCamera c;
  c.zoom(1.0f);
  EXPECT_LT(c.radius(), std::sqrt(145.0f));
  c.zoom(1000.0f);
  EXPECT_FLOAT_EQ(c.radius(), 3.0f);
  c.zoom(-1000.0f);
  EXPECT_FLOAT_EQ(c.radius(), 30.0f);
}

TEST(Camera, PanMovesTheTargetAcrossTheView) {
  OrbitCamera c;
  glm::vec3 f = c.forward();
  c.pan(100.0f, 0.0f, 720.0f);
  glm::vec3 moved = c.target() - glm::vec3(0.0f, 1.0f, 0.0f);
  EXPECT_GT(glm::length(moved), 0.1f);
  EXPECT_NEAR(glm::dot(moved, f), 0.0f, 1e-4f); // in the view plane
  expectNear(c.forward(), f);                   // the view direction is kept
}

TEST(Camera, CentreRayLooksAtTheTarget) {
  OrbitCamera c;
  auto r = c.ray(320.0f, 240.0f, 640.0f, 480.0f);
  expectNear(r.origin, c.eye());
  expectNear(r.dir, c.forward());
}

TEST(Camera, RayProjectsBackToItsPixel) {
  OrbitCamera c;
  c.orbit(37.0f, 12.0f);
  const float w = 640.0f, h = 480.0f;
  const glm::mat4 vp = c.projection(w / h) * c.view();
  for (glm::vec2 px : {glm::vec2(10.0f, 20.0f), glm::vec2(600.0f, 400.0f), glm::vec2(333.0f, 111.0f)}) {
    auto r = c.ray(px.x, px.y, w, h);
    glm::vec4 clip = vp * glm::vec4(r.origin + r.dir * 7.0f, 1.0f);
    glm::vec3 ndc = glm::vec3(clip) / clip.w;
    // Vulkan: x right, y down, depth 0..1.
    EXPECT_NEAR((ndc.x * 0.5f + 0.5f) * w, px.x, 1e-2f);
    EXPECT_NEAR((ndc.y * 0.5f + 0.5f) * h, px.y, 1e-2f);
    EXPECT_GT(ndc.z, 0.0f);
    EXPECT_LT(ndc.z, 1.0f);
  }
}

TEST(Camera, GrabPlaneFacesTheCamera) {
  OrbitCamera c;
  glm::vec3 grab{0.5f, 2.0f, 0.0f};
  auto r = c.ray(100.0f, 100.0f, 640.0f, 480.0f);
  auto hit = tender::render::intersectPlane(r, grab, c.forward());
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(glm::dot(*hit - grab, c.forward()), 0.0f, 1e-4f);
  // A plane behind the eye is never hit; nor is one parallel to the ray.
  EXPECT_FALSE(tender::render::intersectPlane(r, c.eye() - c.forward() * 5.0f, c.forward()).has_value());
  glm::vec3 side = glm::normalize(glm::cross(r.dir, glm::vec3(0.0f, 1.0f, 0.0f)));
  EXPECT_FALSE(tender::render::intersectPlane(r, r.origin + side, side).has_value());
}

TEST(Camera, ViewPointOfTheTargetIsTheMiddle) {
  OrbitCamera c;
  auto v = c.viewPoint(c.target(), 16.0f / 9.0f);
  ASSERT_TRUE(v);
  EXPECT_NEAR(v->x, 0.0f, 1e-5f);
  EXPECT_NEAR(v->y, 0.0f, 1e-5f);
  // y points down, as in Vulkan's clip space; a point behind the eye lands nowhere
  EXPECT_GT(c.viewPoint(c.target() + glm::vec3(0.0f, -1.0f, 0.0f), 1.0f)->y, 0.0f);
  EXPECT_FALSE(c.viewPoint(c.eye() - c.forward(), 1.0f));
}

namespace {

using tender::render::CameraFollow;

// A sheet (one point) tossed from the target to x = -30 over 1.5 s, then resting; the follow
// watches it every 0.1 s and steps at `hz`. Returns the camera's target at each whole second.
std::vector<glm::vec3> followToss(float hz, bool follow) {
  OrbitCamera c;
  CameraFollow f;
  std::vector<glm::vec3> at_seconds;
  const int steps = int(hz * 6.0f), per_watch = int(hz / 10.0f);
  for (int i = 0; i <= steps; ++i) {
    const float t = float(i) / hz;
    const glm::vec3 sheet(-30.0f * std::min(t / 1.5f, 1.0f), 1.0f, 0.0f);
    if (follow && i > 0) f.update(c, 1.0f / hz); // the spring up to time t
    if (follow && i % per_watch == 0) f.watch(std::span(&sheet, 1), c, 16.0f / 9.0f);
    if (i % int(hz) == 0) at_seconds.push_back(c.target());
  }
  return at_seconds;
}

} // namespace

TEST(CameraFollow, KeepsATossedSheetInView) {
  const std::vector<glm::vec3> on = followToss(60.0f, true);
  // Two seconds after the sheet came to rest the camera looks at it
  expectNear(on.back(), {-30.0f, 1.0f, 0.0f}, 0.5f);
  // Off, the camera stays
  for (glm::vec3 t : followToss(60.0f, false)) expectNear(t, {0.0f, 1.0f, 0.0f});
}

TEST(CameraFollow, DoesNotDependOnTheFrameRate) {
  const std::vector<glm::vec3> a = followToss(60.0f, true), b = followToss(30.0f, true), c = followToss(120.0f, true);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  for (size_t i = 0; i < a.size(); ++i) {
    expectNear(a[i], b[i], 1e-2f);
    expectNear(a[i], c[i], 1e-2f);
  }
}

TEST(CameraFollow, LeavesASheetInViewAndOneTheUserLookedAwayFrom) {
  OrbitCamera c;
  CameraFollow f;
  const glm::vec3 near_target = c.target() + glm::vec3(0.3f, 0.2f, 0.0f);
  for (int i = 0; i < 100; ++i) {
    f.watch(std::span(&near_target, 1), c, 1.5f);
    f.update(c, 0.1f);
  }
  expectNear(c.target(), {0.0f, 1.0f, 0.0f});
  // The user pans far away (the demo stops the follow): the sheet is out of view, not followed
  c.pan(5000.0f, 0.0f, 720.0f);
  f.stop();
  const glm::vec3 panned = c.target();
  for (int i = 0; i < 100; ++i) {
    f.watch(std::span(&near_target, 1), c, 1.5f);
    f.update(c, 0.1f);
  }
  EXPECT_FALSE(f.following());
  expectNear(c.target(), panned);
  // Armed (the follow turned on), it goes and finds the sheet
  f.arm();
  for (int i = 0; i < 100; ++i) {
    f.watch(std::span(&near_target, 1), c, 1.5f);
    f.update(c, 0.1f);
  }
  expectNear(c.target(), near_target, 0.5f);
}
