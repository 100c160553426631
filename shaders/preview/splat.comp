#version 450
#extension GL_GOOGLE_include_directive : require
// Compute splatting of the sphere impostors (preview/splat.glsl: the scheme): one invocation per
// sphere walks the pixels of its screen box and, per pixel its silhouette covers, takes part in the
// pixel's atomic nearest-depth (mode.x 0) or nearest-id (mode.x 1) vote. Work per sphere follows its
// pixel area, small for the preview's many small particles.
#include "common/dispatch.glsl"
#include "common/params.h"
#include "preview/splat.glsl"

layout(std140, binding = TS_PREVIEW_PARAMS) uniform ComputeBlock { PreviewComputeParams params; };

layout(local_size_x = 64) in;

void main() {
  uint id = dispatch_item();
  if (id >= params.sizes.x) return;
  vec4 sphere = spheres[id];
  ivec4 box = sphere_pixels(sphere);
  for (int y = box.y; y <= box.w; ++y) {
    for (int x = box.x; x <= box.z; ++x) {
      vec3 p;
      float depth = sphere_hit(sphere, ivec2(x, y), p);
      if (depth >= 1.0) continue;
      uint index = pixel_index(ivec2(x, y));
      uint key = ~floatBitsToUint(depth);
      if (params.mode.x == 0) {
        atomicMax(depth_bits[index], key);
      } else if (depth_bits[index] == key) {
        atomicMax(particle_ids[index], ~id);
      }
    }
  }
}
