#version 450
#include "scene_common.glsl"
// Vertical gradient, as the page's CSS linear-gradient.
layout(location = 0) in float v_t;
layout(location = 0) out vec4 out_color;

void main() { out_color = vec4(mix(scene.bg_top.rgb, scene.bg_bottom.rgb, clamp(v_t, 0.0, 1.0)), 1.0); }
