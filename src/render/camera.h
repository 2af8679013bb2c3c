#pragma once
/// The orbit camera of the scene: spherical coordinates around a target, perspective projection
/// for Vulkan (y down in clip space, depth 0..1), picking rays, the grab plane, and the follow
/// that keeps a tossed sheet in view.
#include <optional>
#include <span>

#include <glm/glm.hpp>

namespace tender::render {

/// A ray in world space (|dir| = 1).
struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 dir{0.0f, 0.0f, -1.0f};
};

/// Orbit camera: the eye sits at `radius` from `target`, at polar angle `phi` (from +Y) and
/// azimuth `theta` (around +Y, from +Z towards +X), as three.js' Spherical does.
class OrbitCamera {
public:
  /// Smallest and largest polar angle (keeps the eye off the poles).
  static constexpr float kMinPhi = 0.1f;
  static constexpr float kMaxPhi = 3.14159265f - 0.1f;
  /// Zoom range (distance to the target) at scale 1.
  static constexpr float kMinRadius = 3.0f;
  static constexpr float kMaxRadius = 30.0f;
  /// Vertical field of view in degrees.
  static constexpr float kFovDegrees = 50.0f;
  /// Near and far clip planes at scale 1.
  static constexpr float kNear = 0.1f;
  static constexpr float kFar = 200.0f;

  /// The spec's start view: eye at (6, 4, 10) looking at (0, 1, 0).
  OrbitCamera();
  /// Places the eye at `eye` looking at `target` (radius and phi clamped to their ranges).
  void lookAt(glm::vec3 eye, glm::vec3 target);
  /// Scales the zoom range and the clip planes (SimParams::view_scale: a scene of another size).
  void setScale(float scale);
  float scale() const { return scale_; }
  float minRadius() const { return kMinRadius * scale_; }
  float maxRadius() const { return kMaxRadius * scale_; }

  /// Orbits by a cursor movement in pixels (right-drag).
  void orbit(float dx_pixels, float dy_pixels);
  /// Zooms by wheel steps (positive = closer), keeping the radius in [3, 30] x scale.
  void zoom(float wheel_steps);
  /// Pans the target by a cursor movement in pixels in a viewport of this height (middle-drag).
  void pan(float dx_pixels, float dy_pixels, float viewport_height);
  /// Moves the target, the eye keeping its place relative to it.
  void setTarget(glm::vec3 target) { target_ = target; }

  /// Eye position, target, spherical coordinates and distance.
  glm::vec3 eye() const;
  glm::vec3 target() const { return target_; }
  float theta() const { return theta_; }
  float phi() const { return phi_; }
  float radius() const { return radius_; }
  /// Unit vector from the eye towards the target.
  glm::vec3 forward() const;

  /// World to view matrix.
  glm::mat4 view() const;
  /// View to clip matrix for Vulkan (y flipped, depth in [0, 1]).
  glm::mat4 projection(float aspect) const;
  /// Ray through pixel (x, y) of a width x height viewport (origin top-left, pixel centres at +0.5).
  Ray ray(float x, float y, float width, float height) const;
  /// Where a point lands in the view: x right and y down in [-1, 1] inside the view; nullopt
  /// behind the near plane.
  std::optional<glm::vec2> viewPoint(glm::vec3 p, float aspect) const;

private:
  glm::vec3 target_{0.0f, 1.0f, 0.0f};
  float radius_ = 1.0f, theta_ = 0.0f, phi_ = 1.0f;
  float scale_ = 1.0f;
};

/// Eases an orbit camera after a sheet that leaves the view (a toss): once the centre of the
/// watched points leaves the middle of the view, the target follows it with a critically damped
/// spring until the centre is back near the middle. The spring is solved exactly over each step,
/// so the motion does not depend on the frame rate.
class CameraFollow {
public:
  /// The spring's smoothing time in seconds (its rate is 2 / kSmoothTime).
  static constexpr float kSmoothTime = 0.5f;
  /// The centre leaving this part of the view ([-1, 1] across) starts the follow...
  static constexpr float kLeaveExtent = 0.8f;
  /// ...and the centre back inside this part ends it.
  static constexpr float kCentredExtent = 0.25f;

  /// Looks at where the sheet is now (points in world space, sampled as often as the caller
  /// likes): starts or ends following, and aims the spring at their centre while following.
  /// A centre that is out of view while not armed (the user looked elsewhere) is not followed.
  void watch(std::span<const glm::vec3> points, const OrbitCamera& camera, float aspect);
  /// Moves the camera's target by dt seconds of the spring.
  void update(OrbitCamera& camera, float dt);
  /// Stops and forgets the spring's velocity; not armed again until the centre is in view (the
  /// user moved the camera).
  void stop();
  /// Follows from the next watch() on even a centre that is out of view now (the follow turned on).
  void arm() { armed_ = true; }
  /// True from the centre leaving the middle of the view until it is back near the middle.
  bool following() const { return following_; }

private:
  bool armed_ = false, following_ = false, moving_ = false;
  glm::vec3 goal_{0.0f}, velocity_{0.0f};
};

/// Centre (mean) of a set of points; the origin for none.
glm::vec3 centreOf(std::span<const glm::vec3> points);

/// Intersection of a ray with the plane through `point` with normal `normal`; nullopt when the
/// ray is parallel to the plane or the plane is behind the origin.
std::optional<glm::vec3> intersectPlane(const Ray& ray, glm::vec3 point, glm::vec3 normal);

} // namespace tender::render
