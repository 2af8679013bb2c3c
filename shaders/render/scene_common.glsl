// Declarations shared by the render shaders: the scene set.
#extension GL_GOOGLE_include_directive : require
#include "render_types.h"

layout(std140, set = 0, binding = RENDER_BIND_SCENE) uniform Scene { SceneUniforms scene; };
layout(set = 0, binding = RENDER_BIND_RECEIPT) uniform sampler2D receipt;
layout(set = 0, binding = RENDER_BIND_SHADOW) uniform sampler2DShadow shadow_map;
layout(std430, set = 0, binding = RENDER_BIND_POS) readonly buffer Positions { vec4 pos[]; };
layout(std430, set = 0, binding = RENDER_BIND_NORMAL) readonly buffer Normals { vec4 normal[]; };
layout(std430, set = 0, binding = RENDER_BIND_UV) readonly buffer Uvs { vec2 uv[]; };
layout(std430, set = 0, binding = RENDER_BIND_TRIANGLES) readonly buffer Triangles { uvec4 triangles[]; };

// Particle index of a vertex of the triangle list (three vertices per live triangle).
uint paperVertex(int vertex_index) {
  uvec4 t = triangles[vertex_index / 3];
  int k = vertex_index % 3;
  return k == 0 ? t.x : (k == 1 ? t.y : t.z);
}

// Fraction of light reaching a world position: PCF over the shadow map, offset along the normal.
float shadowFactor(vec3 world, vec3 n) {
  float texel = scene.floor.w * RENDER_PCF_SPACING;
  vec4 lc = scene.light_view_proj * vec4(world + n * 0.02, 1.0);
  vec3 s = lc.xyz / lc.w;
  vec2 st = s.xy * 0.5 + 0.5;
  if (st.x < 0.0 || st.y < 0.0 || st.x > 1.0 || st.y > 1.0 || s.z > 1.0) return 1.0;
  float sum = 0.0;
  for (int y = -RENDER_PCF_RADIUS; y <= RENDER_PCF_RADIUS; ++y)
    for (int x = -RENDER_PCF_RADIUS; x <= RENDER_PCF_RADIUS; ++x)
      sum += texture(shadow_map, vec3(st + vec2(x, y) * texel, s.z - 0.0015));
  float n_taps = float((2 * RENDER_PCF_RADIUS + 1) * (2 * RENDER_PCF_RADIUS + 1));
  return sum / n_taps;
}
