#version 450
#include "scene_common.glsl"
// Semi-transparent matte ground with a grid, receiving the paper's shadow.
layout(location = 0) in vec3 v_world;
layout(location = 0) out vec4 out_color;

void main() {
  vec3 n = vec3(0.0, 1.0, 0.0);
  vec3 l = scene.light_dir.xyz;
  float lit = shadowFactor(v_world, n);
  vec3 base = scene.ground.rgb;
  // Grid lines one cell apart, anti-aliased over one pixel.
  vec2 g = v_world.xz / scene.floor.z;
  vec2 w = fwidth(g);
  vec2 d = abs(fract(g - 0.5) - 0.5) / max(w, vec2(1e-4));
  float line = 1.0 - clamp(min(d.x, d.y), 0.0, 1.0);
  base = mix(base, base * 0.78, line);
  vec3 color = base * (scene.ambient.rgb + scene.light_dir.w * max(dot(n, l), 0.0) * lit);
  // The shadow also darkens the ground's coverage, so it reads through the transparency.
  float alpha = scene.ground.w + (1.0 - lit) * 0.25;
  out_color = vec4(min(color, vec3(1.0)), alpha);
}
