#version 450
#extension GL_GOOGLE_include_directive : require
// Sphere impostor, fragment stage: the camera ray through this pixel meets the sphere analytically;
// the fragment writes the true depth and normal of the hit (so particles and the ray-cast SDF
// composite by the depth test) or is discarded. In the shadow pass only the depth remains.
#include "preview/bindings.h"
#include "preview/camera.glsl"

in vec3 v_world;
flat in vec4 v_sphere;
flat in vec3 v_color;

layout(location = 0) out vec4 albedo;        // sRGB, a = 1
layout(location = 1) out vec4 normal_layer;  // xyz unit normal, w layer

void main() {
  vec3 dir = ray_direction(v_world);
  // Relative to the centre, from the sprite point (within ~1.5 r of it): no cancellation between
  // the eye distance and the radius.
  vec3 oc = v_world - v_sphere.xyz;
  float r = v_sphere.w;
  float b = dot(oc, dir);
  float c = dot(oc, oc) - r * r;
  float disc = b * b - c;
  if (disc < 0.0) discard;
  float t = -b - sqrt(disc);
  vec3 p = v_world + t * dir;
  gl_FragDepth = window_depth(p);
  albedo = vec4(v_color, 1.0);
  normal_layer = vec4((p - v_sphere.xyz) / r, float(TS_PREVIEW_LAYER_PARTICLE));
}
