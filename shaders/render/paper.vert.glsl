#version 450
#include "scene_common.glsl"
// The paper, pulled from the solver's buffers: three vertices per live triangle.
layout(location = 0) out vec3 v_world;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;

void main() {
  uint i = paperVertex(gl_VertexIndex);
  v_world = pos[i].xyz;
  v_normal = normal[i].xyz;
  v_uv = uv[i];
  gl_Position = scene.view_proj * vec4(v_world, 1.0);
}
