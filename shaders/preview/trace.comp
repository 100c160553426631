#version 450
#extension GL_GOOGLE_include_directive : require
// The compute ray caster and G-buffer resolve (issue 45): one work group per 8 x 8 tile of pixels, so
// neighbouring rays walk the same nodes of the sparse field together. Per pixel: the ray from the near
// plane through the pixel's centre is marched by preview/march.glsl (the fragment ray cast's own code:
// NanoVDB's HDDA over the empty space, sphere tracing and regula falsi at the band) up to the nearest
// splatted sphere; then the pixel's depth becomes plain float bits (for the upload into the depth
// texture) and, unless flags.y asks for depth only (the shadow map), albedo and normal/layer are stored
// as the draws would have written them: the lighting pass reads either path's G-buffer alike.
#include "common/dispatch.glsl"
#include "common/params.h"
#include "preview/splat.glsl"

layout(std140, binding = TS_PREVIEW_PARAMS) uniform ComputeBlock { PreviewComputeParams params; };
#include "preview/march.glsl"

layout(std430, binding = TS_PREVIEW_COLORS) readonly buffer Colors { uint colors[]; };
layout(binding = TS_PREVIEW_IMAGE_ALBEDO, rgba8) uniform writeonly image2D albedo_image;
layout(binding = TS_PREVIEW_IMAGE_NORMAL, rgba16f) uniform writeonly image2D normal_image;

layout(local_size_x = 8, local_size_y = 8) in;

// The SDF along the pixel's ray in front of window depth `limit`: as raycast.frag, with the box's far
// face found by the slab test instead of by rasterising the box. On a hit, its depth and normal.
bool trace_surface(ivec2 pixel, float limit, out float depth, out vec3 n) {
  vec2 window = vec2(pixel) + 0.5;
  vec3 start = world_from_window(window, 0.0);
  vec3 far_point = world_from_window(window, 1.0);
  vec3 dir = normalize(far_point - start);
  vec3 o = to_voxel(start);
  vec3 safe = mix(dir, vec3(1e-20), lessThan(abs(dir), vec3(1e-20)));
  vec3 t0 = -o / safe, t1 = (volume.dims_band.xyz - 1.0 - o) / safe;
  vec3 near3 = min(t0, t1), far3 = max(t0, t1);
  float t = max(max(near3.x, near3.y), max(near3.z, 0.0));
  float t_exit = min(min(far3.x, far3.y), min(far3.z, length(far_point - start) / volume.origin_voxel.w));
  if (limit < 1.0) t_exit = min(t_exit, dot(world_from_window(window, limit) - start, dir) / volume.origin_voxel.w);
  depth = 1.0;
  n = vec3(0.0);
  if (t >= t_exit) return false;
  float t_hit = t;
  bool entered_inside = sdf_at(o + t * dir) <= 0.0;  // the near plane cuts the solid
  if (!entered_inside && !find_surface(o, dir, t, t_exit, t_hit)) return false;
  depth = window_depth(start + dir * (t_hit * volume.origin_voxel.w));
  if (params.flags.y == 0) n = entered_inside ? -dir : sdf_normal(o + t_hit * dir);
  return true;
}

// Albedo and normal/layer of the nearest sphere at the pixel (background zeros when none).
void store_particle(ivec2 pixel, uint id) {
  if (id == 0xffffffffu) {
    imageStore(albedo_image, pixel, vec4(0.0));
    imageStore(normal_image, pixel, vec4(0.0));
    return;
  }
  vec4 sphere = spheres[id];
  vec3 p;
  sphere_hit(sphere, pixel, p);
  vec3 color = params.flags.x == 1 ? unpackUnorm4x8(colors[id]).rgb : params.particle_color.xyz;
  imageStore(albedo_image, pixel, vec4(color, 1.0));
  imageStore(normal_image, pixel, vec4((p - sphere.xyz) / sphere.w, float(TS_PREVIEW_LAYER_PARTICLE)));
}

void main() {
  uint tile = dispatch_group();
  ivec2 pixel = ivec2(tile % params.sizes.y, tile / params.sizes.y) * 8 + ivec2(gl_LocalInvocationID.xy);
  if (pixel.x >= int(params.sizes.z) || pixel.y >= int(params.sizes.w)) return;
  uint index = pixel_index(pixel);
  uint bits = depth_bits[index];
  float particle = bits == 0u ? 1.0 : uintBitsToFloat(~bits);  // 0: no sphere voted (splat.glsl)
  float depth = 1.0;
  vec3 n = vec3(0.0);
  bool surface = params.flags.w == 1 && trace_surface(pixel, particle, depth, n);
  depth_bits[index] = floatBitsToUint(surface ? depth : particle);
  if (params.flags.y == 1) return;
  if (surface) {
    imageStore(albedo_image, pixel, vec4(params.surface_color.xyz, 1.0));
    imageStore(normal_image, pixel, vec4(n, float(TS_PREVIEW_LAYER_SURFACE)));
  } else {
    store_particle(pixel, ~particle_ids[index]);
  }
}
