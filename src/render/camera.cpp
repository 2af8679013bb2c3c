#include "camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace tender::render {

OrbitCamera::OrbitCamera() { lookAt({6.0f, 4.0f, 10.0f}, {0.0f, 1.0f, 0.0f}); }

void OrbitCamera::lookAt(glm::vec3 eye_pos, glm::vec3 target) {
  target_ = target;
  glm::vec3 d = eye_pos - target;
  radius_ = std::clamp(glm::length(d), kMinRadius, kMaxRadius);
  float len = glm::length(d);
  phi_ = std::clamp(len > 0.0f ? std::acos(std::clamp(d.y / len, -1.0f, 1.0f)) : 1.0f, kMinPhi, kMaxPhi);
  theta_ = std::atan2(d.x, d.z);
}

void OrbitCamera::orbit(float dx_pixels, float dy_pixels) {
  // Half a degree per pixel, dragging the scene with the cursor.
  constexpr float kRadiansPerPixel = 0.005f;
  theta_ -= dx_pixels * kRadiansPerPixel;
  phi_ = std::clamp(phi_ - dy_pixels * kRadiansPerPixel, kMinPhi, kMaxPhi);
}

void OrbitCamera::zoom(float wheel_steps) {
  // Each wheel step moves 10% closer (or further).
  radius_ = std::clamp(radius_ * std::pow(0.9f, wheel_steps), kMinRadius, kMaxRadius);
}

void OrbitCamera::pan(float dx_pixels, float dy_pixels, float viewport_height) {
  // One pixel moves the target by the size of a pixel at the target's depth.
  float world_per_pixel = 2.0f * radius_ * std::tan(glm::radians(kFovDegrees) * 0.5f) / std::max(viewport_height, 1.0f);
  glm::vec3 f = forward();
  glm::vec3 right = glm::normalize(glm::cross(f, glm::vec3(0.0f, 1.0f, 0.0f)));
  glm::vec3 up = glm::cross(right, f);
  target_ += (-dx_pixels * right + dy_pixels * up) * world_per_pixel;
}

glm::vec3 OrbitCamera::eye() const {
  float s = std::sin(phi_);
  return target_ + radius_ * glm::vec3(s * std::sin(theta_), std::cos(phi_), s * std::cos(theta_));
}

glm::vec3 OrbitCamera::forward() const { return glm::normalize(target_ - eye()); }

glm::mat4 OrbitCamera::view() const { return glm::lookAtRH(eye(), target_, glm::vec3(0.0f, 1.0f, 0.0f)); }

glm::mat4 OrbitCamera::projection(float aspect) const {
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(kFovDegrees), aspect, 0.1f, 200.0f);
  p[1][1] *= -1.0f; // Vulkan clip space has y pointing down
  return p;
}

Ray OrbitCamera::ray(float x, float y, float width, float height) const {
  float ndc_x = 2.0f * x / width - 1.0f;
  float ndc_y = 1.0f - 2.0f * y / height;
  float tan_half = std::tan(glm::radians(kFovDegrees) * 0.5f);
  glm::vec3 f = forward();
  glm::vec3 right = glm::normalize(glm::cross(f, glm::vec3(0.0f, 1.0f, 0.0f)));
  glm::vec3 up = glm::cross(right, f);
  glm::vec3 d = f + right * (ndc_x * tan_half * width / height) + up * (ndc_y * tan_half);
  return {eye(), glm::normalize(d)};
}

std::optional<glm::vec3> intersectPlane(const Ray& ray, glm::vec3 point, glm::vec3 normal) {
  float denom = glm::dot(ray.dir, normal);
  if (std::abs(denom) < 1e-6f) return std::nullopt;
  float t = glm::dot(point - ray.origin, normal) / denom;
  if (t < 0.0f) return std::nullopt;
  return ray.origin + ray.dir * t;
}

} // namespace tender::render
