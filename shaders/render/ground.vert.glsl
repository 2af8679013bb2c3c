#version 450
#include "scene_common.glsl"
// The ground: a square of half size scene.floor.y at the floor height, two triangles.
layout(location = 0) out vec3 v_world;

void main() {
  const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
  vec2 c = corners[gl_VertexIndex] * scene.floor.y;
  // A hair below the floor so that paper resting on it wins the depth test.
  v_world = vec3(c.x, scene.floor.x - 0.004, c.y);
  gl_Position = scene.view_proj * vec4(v_world, 1.0);
}
