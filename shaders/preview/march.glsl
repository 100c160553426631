// The ray cast's march, shared by the fragment ray cast (raycast.frag) and the compute ray caster
// (trace.comp), so both paths find the same surface. The includer declares `params` (a struct with
// flags.z: most refinement steps per crossing, steps.x: shortest step [voxels]) before including it.
#ifndef TETRASAND_PREVIEW_MARCH_GLSL
#define TETRASAND_PREVIEW_MARCH_GLSL

#include "preview/volume.glsl"

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

#endif
