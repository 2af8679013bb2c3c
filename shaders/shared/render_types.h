// GPU-visible structs and bindings of the renderer, shared by GLSL and C++.
// In C++ this file is included inside `namespace shaderio { using namespace glm; }`.
#ifndef RENDER_TYPES_H
#define RENDER_TYPES_H
#include "prelude.h"

// Descriptor bindings of the scene set (one set, shared by every render pass)
#define RENDER_BIND_SCENE 0
#define RENDER_BIND_RECEIPT 1
#define RENDER_BIND_SHADOW 2
#define RENDER_BIND_POS 3
#define RENDER_BIND_NORMAL 4
#define RENDER_BIND_UV 5
#define RENDER_BIND_TRIANGLES 6

// Side of the square shadow map in texels
#define RENDER_SHADOW_SIZE 2048
// PCF kernel radius in taps (a (2r+1)^2 grid of comparisons)
#define RENDER_PCF_RADIUS 2
// Distance between PCF taps in shadow-map texels (softer penumbrae when larger)
#define RENDER_PCF_SPACING 1.75

/// Per-frame inputs of every render pass (one uniform buffer, std140 == C++ layout).
struct SceneUniforms {
  mat4 view_proj;       // world to clip of the camera
  mat4 light_view_proj; // world to clip of the shadow map (depth 0..1)
  vec4 eye;             // xyz camera position
  vec4 light_dir;       // xyz unit direction towards the light, w = intensity
  vec4 ambient;         // rgb ambient light (colour x intensity)
  vec4 paper;           // rgb paper tint, w = roughness
  vec4 ground;          // rgb ground colour, w = opacity
  vec4 bg_top;          // rgb background at the top of the screen
  vec4 bg_bottom;       // rgb background at the bottom
  vec4 floor;           // x = floor y, y = ground half size, z = grid cell, w = 1 / shadow map size
};

// A corner's normal turns from the particle's smooth normal to its triangle's own where the two
// differ by more than this (cos 12 degrees): where the sheet is bent through some 24 degrees at one
// hinge, a crease, the triangles on either side are shaded as the flat facets they are.
#define RENDER_CREASE_COS 0.978f

/// The normal of a triangle's corner: the particle's smooth normal, or the triangle's own (of
/// corners a, b, c, counter-clockwise) across a crease (RENDER_CREASE_COS). A triangle of no area
/// keeps the smooth normal.
SIM_INLINE vec3 cornerNormal(vec3 smooth_normal, vec3 a, vec3 b, vec3 c) {
  vec3 f = cross(b - a, c - a);
  float len = length(f);
  if (!(len > 1e-12f)) return smooth_normal;
  f = f / len;
  return dot(f, smooth_normal) < RENDER_CREASE_COS ? f : smooth_normal;
}

#endif
