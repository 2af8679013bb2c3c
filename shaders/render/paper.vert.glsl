#version 450
#include "scene_common.glsl"
// The paper, pulled from the solver's buffers: three vertices per live triangle, each with its
// corner's normal (cornerNormal).
layout(location = 0) out vec3 v_world;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;

void main() {
  uint i = paperVertex(gl_VertexIndex);
  uvec4 t = triangles[gl_VertexIndex / 3];
  v_world = pos[i].xyz;
  // Smooth across the sheet, split into flat facets along a crease
  v_normal = cornerNormal(normal[i].xyz, pos[t.x].xyz, pos[t.y].xyz, pos[t.z].xyz);
  v_uv = uv[i];
  gl_Position = scene.view_proj * vec4(v_world, 1.0);
}
