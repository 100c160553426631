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

// Sphere tracing on the trilinear field over [t, t_end] (voxels along `dir` from `o`); the first
// sign change is refined by regula falsi into t_hit.
bool trace_window(vec3 o, vec3 dir, float t, float t_end, out float t_hit) {
  float f = sdf_at(o + t * dir);
  t_hit = t;
  for (int i = 0; i < params.flags.z; ++i) {
    float t_next = min(t + max(f, params.steps.x), t_end);
    float f_next = sdf_at(o + t_next * dir);
    if (f_next <= 0.0) {
      float a = t, fa = f, b = t_next, fb = f_next;
      for (int k = 0; k < 6; ++k) {
        float m = a + (b - a) * clamp(fa / (fa - fb), 0.1, 0.9);
        float fm = sdf_at(o + m * dir);
        if (fm > 0.0) {
          a = m;
          fa = fm;
        } else {
          b = m;
          fb = fm;
        }
      }
      t_hit = a + (b - a) * (fa / max(fa - fb, 1e-12));
      return true;
    }
    if (t_next >= t_end) return false;
    t = t_next;
    f = f_next;
  }
  return false;
}

// The first crossing of the zero level in [t, t_exit]. NanoVDB's hierarchical DDA walks the tree:
// nodes and tiles without band voxels are crossed in one step each, and the voxels of the band's
// leaves one by one (cells offset by half a voxel, so a cell's value is its nearest voxel centre's).
// Where a voxel lies within kNearSurface voxels of the zero level the trilinear field may cross
// zero within a voxel of the ray (its value differs from the nearest centre's by at most
// sqrt(3)/2 x sqrt(3) = 1.5 voxels), so the field is sphere-traced from two voxels before that voxel
// to two after. Conservative at silhouettes: a grazing ray is traced wherever a crossing could be.
const float kNearSurface = 1.6;  // [voxels]
bool find_surface(vec3 o, vec3 dir, float t, float t_exit, out float t_hit) {
  ensure_volume_reader();
  pnanovdb_buf_t buf = pnanovdb_buf_t(0u);  // unused by the reads: set, so nothing reads an undefined value
  t_hit = t;
  pnanovdb_vec3_t origin = o + vec3(field_params.index_offset.xyz) + vec3(0.5);
  pnanovdb_vec3_t direction = dir;
  float t_min = t, t_max = t_exit;
  pnanovdb_vec3_t box_min = pnanovdb_coord_to_vec3(pnanovdb_root_get_bbox_min(buf, volume_reader.accessor.root));
  pnanovdb_vec3_t box_max = pnanovdb_coord_to_vec3(pnanovdb_coord_add(
      pnanovdb_root_get_bbox_max(buf, volume_reader.accessor.root), pnanovdb_coord_uniform(1)));
  if (!pnanovdb_hdda_ray_clip(box_min, box_max, origin, t_min, direction, t_max)) return false;
  float near_surface = kNearSurface * volume.origin_voxel.w;  // field values are in world units
  float traced_to = t_min;  // the field has no crossing before here
  pnanovdb_vec3_t pos = pnanovdb_hdda_ray_start(origin, t_min, direction);
  pnanovdb_coord_t ijk = pnanovdb_hdda_pos_to_ijk(pos);
  int dim = int(field_dim(volume_reader.accessor, ijk));
  pnanovdb_hdda_t hdda;
  pnanovdb_hdda_init(hdda, origin, t_min, direction, t_max, dim);
  while (pnanovdb_hdda_step(hdda)) {
    pnanovdb_vec3_t next = pnanovdb_hdda_ray_start(origin, hdda.tmin + 1.0001, direction);
    ijk = pnanovdb_hdda_pos_to_ijk(next);
    dim = int(field_dim(volume_reader.accessor, ijk));
    pnanovdb_hdda_update(hdda, origin, direction, dim);
    if (hdda.dim > 1 || !field_is_active(volume_reader.accessor, ijk)) {
      continue;
    }
    while (pnanovdb_hdda_step(hdda) &&
           field_is_active(volume_reader.accessor, hdda.voxel)) {
      pnanovdb_address_t address = field_value_address(volume_reader.accessor, hdda.voxel);
      float value = pnanovdb_read_float(buf, address);
      float t_end = min(hdda.tmin + 2.0, t_exit);
      if (value < near_surface && t_end > traced_to) {
        if (trace_window(o, dir, max(traced_to, hdda.tmin - 2.0), t_end, t_hit)) return true;
        traced_to = t_end;
      }
    }
  }
  return false;
}

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
