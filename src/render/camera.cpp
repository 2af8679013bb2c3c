#include "camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace tender::render {

OrbitCamera::OrbitCamera() { lookAt({6.0f, 4.0f, 10.0f}, {0.0f, 1.0f, 0.0f}); }

void OrbitCamera::lookAt(glm::vec3 eye_pos, glm::vec3 target) {
  target_ = target;
  glm::vec3 d = eye_pos - target;
  radius_ = std::clamp(glm::length(d), minRadius(), maxRadius());
  float len = glm::length(d);
  phi_ = std::clamp(len > 0.0f ? std::acos(std::clamp(d.y / len, -1.0f, 1.0f)) : 1.0f, kMinPhi, kMaxPhi);
  theta_ = std::atan2(d.x, d.z);
}

void OrbitCamera::setScale(float scale) {
  scale_ = scale;
  radius_ = std::clamp(radius_, minRadius(), maxRadius());
}

void OrbitCamera::orbit(float dx_pixels, float dy_pixels) {
  // Half a degree per pixel, dragging the scene with the cursor.
  constexpr float kRadiansPerPixel = 0.005f;
  theta_ -= dx_pixels * kRadiansPerPixel;
  phi_ = std::clamp(phi_ - dy_pixels * kRadiansPerPixel, kMinPhi, kMaxPhi);
}

void OrbitCamera::zoom(float wheel_steps) {
  // Each wheel step moves 10% closer (or further).
  radius_ = std::clamp(radius_ * std::pow(0.9f, wheel_steps), minRadius(), maxRadius());
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
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(kFovDegrees), aspect, kNear * scale_, kFar * scale_);
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

std::optional<glm::vec2> OrbitCamera::viewPoint(glm::vec3 p, float aspect) const {
  const glm::vec4 clip = projection(aspect) * view() * glm::vec4(p, 1.0f);
  if (clip.w <= kNear * scale_) return std::nullopt;
  return glm::vec2(clip) / clip.w;
}

namespace {

// Whether a point lands inside the middle `extent` of the view.
bool insideView(const OrbitCamera& camera, glm::vec3 p, float aspect, float extent) {
  const auto v = camera.viewPoint(p, aspect);
  return v && std::abs(v->x) <= extent && std::abs(v->y) <= extent;
}

} // namespace

glm::vec3 centreOf(std::span<const glm::vec3> points) {
  glm::vec3 sum(0.0f);
  for (glm::vec3 p : points) sum += p;
  return points.empty() ? sum : sum / float(points.size());
}

void CameraFollow::watch(std::span<const glm::vec3> points, const OrbitCamera& camera, float aspect) {
  if (points.empty()) return;
  const glm::vec3 centre = centreOf(points);
  if (insideView(camera, centre, aspect, kLeaveExtent)) armed_ = true;
  if (!following_ && armed_ && !insideView(camera, centre, aspect, kLeaveExtent)) {
    following_ = true;
    if (!moving_) velocity_ = glm::vec3(0.0f);
    moving_ = true;
  }
  if (!following_) return;
  goal_ = centre;
  // Back near the middle: the spring settles on this centre and the follow ends
  if (insideView(camera, centre, aspect, kCentredExtent)) following_ = false;
}

void CameraFollow::update(OrbitCamera& camera, float dt) {
  if (!moving_ || dt <= 0.0f) return;
  // The critically damped spring's exact step: x(t) = (x0 + (v0 + w x0) t) e^(-w t)
  const float w = 2.0f / kSmoothTime, e = std::exp(-w * dt);
  const glm::vec3 x = camera.target() - goal_;
  const glm::vec3 k = (velocity_ + w * x) * dt;
  velocity_ = (velocity_ - w * k) * e;
  camera.setTarget(goal_ + (x + k) * e);
  // Settled: within a millimetre and nearly at rest
  if (!following_ && glm::length(camera.target() - goal_) < 1e-3f && glm::length(velocity_) < 1e-2f) moving_ = false;
}

void CameraFollow::stop() {
  armed_ = following_ = moving_ = false;
  velocity_ = glm::vec3(0.0f);
}

std::optional<glm::vec3> intersectPlane(const Ray& ray, glm::vec3 point, glm::vec3 normal) {
  float denom = glm::dot(ray.dir, normal);
  if (std::abs(denom) < 1e-6f) return std::nullopt;
  float t = glm::dot(point - ray.origin, normal) / denom;
  if (t < 0.0f) return std::nullopt;
  return ray.origin + ray.dir * t;
}

} // namespace tender::render
