// The SDF as the preview reads it: a 3D texture of signed distance in voxel units (R32F or R16F)
// with hardware trilinear filtering. Voxel centres sit at integer voxel coordinates.
#ifndef TETRASAND_PREVIEW_VOLUME_GLSL
#define TETRASAND_PREVIEW_VOLUME_GLSL

#include "preview/bindings.h"

layout(binding = TS_PREVIEW_UNIT_VOLUME) uniform sampler3D volume;
uniform vec3 volume_origin;  // voxel (0,0,0)'s centre, relative to the scene centre [m]
uniform float voxel_size;    // [m]
uniform vec3 volume_dims;    // voxels along x, y, z
uniform float band;          // |distance| saturates here [voxels]

vec3 to_voxel(vec3 p) { return (p - volume_origin) / voxel_size; }

// Signed distance [voxels] at voxel coordinates u.
float sdf_at(vec3 u) { return texture(volume, (u + 0.5) / volume_dims).r; }

// Unit outward normal: central differences one voxel apart, so the normal varies smoothly across
// voxel faces (the trilinear interpolant's own gradient jumps there and would show as banding).
vec3 sdf_normal(vec3 u) {
  vec3 g = vec3(sdf_at(u + vec3(1, 0, 0)) - sdf_at(u - vec3(1, 0, 0)),
                sdf_at(u + vec3(0, 1, 0)) - sdf_at(u - vec3(0, 1, 0)),
                sdf_at(u + vec3(0, 0, 1)) - sdf_at(u - vec3(0, 0, 1)));
  float len = length(g);
  return len > 1e-12 ? g / len : vec3(0.0, 0.0, 1.0);
}

#endif
