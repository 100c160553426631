// Spheres splatted by compute (preview/splat.comp, preview/trace.comp): per sphere the pixels its
// silhouette may cover, per pixel the exact hit of the pixel's ray with the sphere.
//
// The atomic scheme (GL 4.5 core has 32-bit atomics on storage-buffer uints, no 64-bit ones), two
// passes of one program so both compute bit-identical depths:
//   1. depths: per covered pixel atomicMax(depth_bits, ~floatBitsToUint(window depth)). Window depths
//      are positive floats, whose bits order as uints do, so the largest complement is the nearest
//      sphere, and a zero-filled buffer (~0 = 0xffffffff, above any depth's bits) means none.
//   2. ids: per covered pixel whose depth equals the winner's bit for bit, atomicMax(ids, ~id): among
//      spheres at exactly the same depth the smallest id wins, so the picture does not depend on the
//      order the invocations ran in.
// trace.comp then shades from the id (the hit recomputed for the normal) and writes plain depth bits.
#ifndef TETRASAND_PREVIEW_SPLAT_GLSL
#define TETRASAND_PREVIEW_SPLAT_GLSL

#include "preview/bindings.h"
#include "preview/camera.glsl"

layout(std430, binding = TS_PREVIEW_SPHERES) readonly buffer Spheres { vec4 spheres[]; };
layout(std430, binding = TS_PREVIEW_DEPTH_BITS) buffer DepthBits { uint depth_bits[]; };
layout(std430, binding = TS_PREVIEW_PARTICLE_IDS) buffer ParticleIds { uint particle_ids[]; };

uint pixel_index(ivec2 pixel) { return uint(pixel.y * int(camera.viewport.x) + pixel.x); }

// The first and last pixel (xy, zw; inclusive) whose centres the sphere's silhouette may cover; z < x
// when none. The bound is the sprite particles.vert draws: the silhouette cone crosses the plane
// through the centre, square to the ray, in a circle the sprite holds (1.02 of its radius), so the
// sprite's projected corners bound the silhouette's pixels.
ivec4 sphere_pixels(vec4 sphere) {
  vec3 c = sphere.xyz;
  float r = sphere.w;
  vec3 u = camera.right.xyz, v = camera.up.xyz;
  float half_size = r;
  if (camera.lens.x == 0) {
    vec3 to_center = c - camera.eye.xyz;
    float dist = length(to_center);
    if (dist <= 1.0001 * r) return ivec4(0, 0, -1, -1);  // the eye is inside the sphere: dropped, as by the draw
    vec3 w = to_center / dist;
    u = normalize(abs(dot(w, camera.up.xyz)) < 0.99 ? cross(w, camera.up.xyz) : cross(w, camera.right.xyz));
    v = cross(u, w);
    half_size = r * dist / sqrt(dist * dist - r * r);
  }
  vec2 lo = vec2(3.0e38), hi = vec2(-3.0e38);
  for (int k = 0; k < 4; ++k) {
    vec2 corner = vec2((k & 1) == 0 ? -1.0 : 1.0, (k & 2) == 0 ? -1.0 : 1.0);
    vec4 clip = camera.view_projection * vec4(c + (corner.x * u + corner.y * v) * (1.02 * half_size), 1.0);
    if (clip.w <= 0.0) {  // a corner behind the eye: its projection says nothing, so take the whole image
      lo = vec2(0.0);
      hi = camera.viewport.xy;
      break;
    }
    vec2 window = (0.5 * clip.xy / clip.w + 0.5) * camera.viewport.xy;
    lo = min(lo, window);
    hi = max(hi, window);
  }
  // Pixel centres x + 0.5 inside [lo, hi], clamped to the image as floats (no int conversion overflows).
  vec2 first = clamp(ceil(lo - 0.5), vec2(0.0), camera.viewport.xy);
  vec2 last = clamp(floor(hi - 0.5), vec2(-1.0), camera.viewport.xy - 1.0);
  return ivec4(ivec2(first), ivec2(last));
}

// The window depth (0 near .. 1 far) where the ray through the pixel's centre first meets the sphere,
// and the hit; 1.0 for a miss or a hit outside the depth range (the draw clips those). The closest
// approach to the centre, not the quadratic from the ray's origin: no cancellation between the eye
// distance and the radius (the draw starts from the sprite point for the same reason).
float sphere_hit(vec4 sphere, ivec2 pixel, out vec3 p) {
  vec3 start = world_from_window(vec2(pixel) + 0.5, 0.0);
  bool parallel = camera.lens.x == 1;
  vec3 o = parallel ? start : camera.eye.xyz;
  vec3 dir = parallel ? camera.forward.xyz : normalize(start - camera.eye.xyz);
  float along = dot(sphere.xyz - o, dir);
  vec3 off = o + along * dir - sphere.xyz;
  float h2 = sphere.w * sphere.w - dot(off, off);
  p = o;
  if (h2 < 0.0) return 1.0;
  p = o + (along - sqrt(h2)) * dir;
  float depth = window_depth(p);
  return depth >= 0.0 && depth < 1.0 ? depth : 1.0;
}

#endif
