#version 450
#extension GL_GOOGLE_include_directive : require
// Turns the scan-converted slabs copied into the SDF texture into the field DenseSdf holds: band
// voxels (|d| < band) get their distance in world units, every other voxel (never reached, or
// reached beyond the band by a prism's quarter-voxel margin) gets +-band with the sign of the CPU
// flood fill and a zero gradient. `precise` keeps d * h one correctly rounded multiply, as on the host.
#include "sdf/bindings.h"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 4) in;
layout(rgba32f, binding = TS_SDF_FIELD_IMAGE) uniform image3D field;
// Bit v of the grid (linear index x + dims.x * (y + dims.y * z)) set: an inside voxel off the band.
layout(std430, binding = TS_SDF_INSIDE_BITS) readonly buffer InsideBits { uint inside_bits[]; };

uniform ivec3 dims;
uniform float band;        // half-width [voxels]
uniform float voxel_size;  // [world units]

void main() {
  ivec3 p = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(p, dims))) return;
  vec4 v = imageLoad(field, p);
  if (abs(v.w) < band) {
    precise float d = v.w * voxel_size;
    imageStore(field, p, vec4(v.xyz, d));
    return;
  }
  uint index = uint(p.x) + uint(dims.x) * (uint(p.y) + uint(dims.y) * uint(p.z));
  bool inside = ((inside_bits[index >> 5u] >> (index & 31u)) & 1u) != 0u;
  precise float far = band * voxel_size;
  imageStore(field, p, vec4(0.0, 0.0, 0.0, inside ? -far : far));
}
