#version 450
#include "scene_common.glsl"
// Depth-only pass of the paper from the light.
void main() {
  uint i = paperVertex(gl_VertexIndex);
  gl_Position = scene.light_view_proj * vec4(pos[i].xyz, 1.0);
}
