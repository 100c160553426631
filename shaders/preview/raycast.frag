#version 450
#extension GL_GOOGLE_include_directive : require
// Ray casting, fragment stage: from where the pixel's ray enters the box to the far face, or to the
// particle already drawn at this pixel (the hybrid: where a particle covers the pixel only the
// stretch in front of it is marched, and nothing when it lies in front of the box). NanoVDB's HDDA
// skips the empty space (nodes and tiles without band voxels) and walks the band's voxels; around
// each voxel near the zero level, sphere tracing on the trilinear field (steps of the sampled distance) finds the
// crossing, refined by regula falsi. The normal is the SDF's gradient; depth is the hit's true depth.
#include "preview/bindings.h"
#include "preview/camera.glsl"
#include "preview/volume.glsl"

layout(binding = TS_PREVIEW_UNIT_PARTICLE_DEPTH) uniform sampler2D particle_depth;  // window depth of the particle layer (1: none)
#include "common/params.h"
layout(std140, binding = TS_PREVIEW_PARAMS) uniform RaycastBlock { RaycastParams params; };

in vec3 v_world;

#include "preview/march.glsl"

layout(location = 0) out vec4 albedo;
layout(location = 1) out vec4 normal_layer;

void main() {
  // The ray from the near plane to the far face, in voxel units.
  vec3 start = world_from_window(gl_FragCoord.xy, 0.0);
  vec3 segment = v_world - start;
  float seg_length = length(segment);
  if (seg_length <= 0.0) discard;
  vec3 dir = segment / seg_length;
  vec3 o = to_voxel(start);
  float t_exit = seg_length / volume.origin_voxel.w;
  if (params.flags.x == 1) {
    float particle = texelFetch(particle_depth, ivec2(gl_FragCoord.xy), 0).r;
    if (particle < 1.0) {
      t_exit = min(t_exit, dot(world_from_window(gl_FragCoord.xy, particle) - start, dir) / volume.origin_voxel.w);
    }
  }
  // Entry: the slab test against the voxel-centre box [0, dims - 1].
  vec3 safe = mix(dir, vec3(1e-20), lessThan(abs(dir), vec3(1e-20)));
  vec3 t0 = -o / safe, t1 = (volume.dims_band.xyz - 1.0 - o) / safe;
  vec3 near3 = min(t0, t1);
  float t = max(max(near3.x, near3.y), max(near3.z, 0.0));
  if (t >= t_exit) discard;

  float t_hit = t;
  bool entered_inside = sdf_at(o + t * dir) <= 0.0;  // the near plane cuts the solid
  bool hit = entered_inside || find_surface(o, dir, t, t_exit, t_hit);
  if (!hit) discard;

  vec3 p = start + dir * (t_hit * volume.origin_voxel.w);
  gl_FragDepth = window_depth(p);
  if (params.flags.y == 1) return;
  vec3 n = entered_inside ? -dir : sdf_normal(o + t_hit * dir);
  albedo = vec4(params.surface_color.xyz, 1.0);
  normal_layer = vec4(n, float(TS_PREVIEW_LAYER_SURFACE));
}
