#version 450
#extension GL_GOOGLE_include_directive : require
// Particles as sphere impostors (thesis 5.2): each sphere is a sprite of two triangles (six vertices
// from gl_VertexID, no vertex buffers) facing the ray to its centre and just large enough to hold the
// sphere's silhouette; the fragment stage intersects the ray with the true sphere. Sprites are
// built here rather than as GL_POINTS because point sizes are capped (llvmpipe: 255 pixels) and a
// perspective silhouette is not centred on the projected centre.
#include "preview/bindings.h"
#include "preview/camera.glsl"

layout(std430, binding = TS_PREVIEW_SPHERES) readonly buffer Spheres { vec4 spheres[]; };
layout(std430, binding = TS_PREVIEW_COLORS) readonly buffer Colors { uint colors[]; };

#include "common/params.h"
layout(std140, binding = TS_PREVIEW_PARAMS) uniform ParticleBlock { ParticleParams params; };

out vec3 v_world;              // the sprite point, relative world [m]
flat out vec4 v_sphere;        // centre (relative world) and radius [m]
flat out vec3 v_color;         // sRGB

const vec2 kCorners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));

void main() {
  int index = gl_VertexID / 6;
  vec2 corner = kCorners[gl_VertexID % 6];
  vec4 sphere = spheres[index];
  vec3 c = sphere.xyz;
  float r = sphere.w;
  vec3 u = camera.right.xyz, v = camera.up.xyz;
  float half_size = r;
  if (camera.lens.x == 0) {
    vec3 to_center = c - camera.eye.xyz;
    float dist = length(to_center);
    if (dist <= 1.0001 * r) {  // the eye is inside the sphere: drop it
      gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
      return;
    }
    // The silhouette cone (half-angle asin(r / dist)) crosses the plane through the centre,
    // perpendicular to the ray, in a circle of radius r dist / sqrt(dist^2 - r^2).
    vec3 w = to_center / dist;
    u = normalize(abs(dot(w, camera.up.xyz)) < 0.99 ? cross(w, camera.up.xyz) : cross(w, camera.right.xyz));
    v = cross(u, w);
    half_size = r * dist / sqrt(dist * dist - r * r);
  }
  v_world = c + (corner.x * u + corner.y * v) * (1.02 * half_size);
  v_sphere = sphere;
  v_color = params.flags.x == 1 ? unpackUnorm4x8(colors[index]).rgb : params.color.xyz;
  gl_Position = camera.view_projection * vec4(v_world, 1.0);
}
