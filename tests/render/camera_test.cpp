// The orbit camera: the spec's start view, clamps, rays and the grab plane.
#include <gtest/gtest.h>

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
