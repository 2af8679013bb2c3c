#version 450
#include "scene_common.glsl"
// Double-sided physically based paper: Lambert diffuse plus GGX specular (metalness 0).
layout(location = 0) in vec3 v_world;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 0) out vec4 out_color;

const float kPi = 3.14159265;

void main() {
  vec3 v = normalize(scene.eye.xyz - v_world);
  vec3 n = normalize(v_normal);
  // Both faces are lit: the normal faces the viewer.
  if (dot(n, v) < 0.0) n = -n;
  vec3 l = scene.light_dir.xyz;
  vec3 albedo = texture(receipt, v_uv).rgb * scene.paper.rgb;

  float ndl = max(dot(n, l), 0.0);
  float ndv = max(dot(n, v), 1e-4);
  vec3 h = normalize(l + v);
  float ndh = max(dot(n, h), 0.0);
  float vdh = max(dot(v, h), 0.0);
  float a = scene.paper.w * scene.paper.w;
  float a2 = a * a;
  float dd = ndh * ndh * (a2 - 1.0) + 1.0;
  float D = a2 / (kPi * dd * dd);
  float k = a * 0.5;
  float G = (ndl / (ndl * (1.0 - k) + k)) * (ndv / (ndv * (1.0 - k) + k));
  float F = 0.04 + 0.96 * pow(1.0 - vdh, 5.0);
  float spec = D * G * F / max(4.0 * ndl * ndv, 1e-4);

  float lit = shadowFactor(v_world, n);
  vec3 direct = scene.light_dir.w * ndl * lit * (albedo * (1.0 - F) + vec3(spec * kPi));
  vec3 color = albedo * scene.ambient.rgb + direct;
  out_color = vec4(min(color, vec3(1.0)), 1.0);
}
