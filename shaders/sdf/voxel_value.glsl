// The value one triangle gives a voxel centre: the exact distance to its closest point and the sign of
// the angle-weighted pseudonormal of the feature that holds that point (Baerentzen & Aanaes 2005).
// The one definition for both scan conversions (scan_convert.frag and the compute path's
// scan_bricks.comp), so they agree to the bit on every voxel they both reach.
#ifndef TETRASAND_SDF_VOXEL_VALUE_GLSL
#define TETRASAND_SDF_VOXEL_VALUE_GLSL

#include "sdf/closest_point.glsl"

// From the triangle's closest point to p [voxels]; *pseudonormal receives the closest feature's.
// `precise`: the compute path finds its nearest triangle by comparing these distances' bits in one
// kernel and recomputes the value in another, so no kernel may contract the arithmetic differently.
vec3 triangle_delta(vec3 p, SdfTriangle t, out vec3 pseudonormal) {
  int feature;
  // Work relative to vertex 0 so the error does not grow with the grid coordinate.
  vec3 a = t.vertex[0].xyz;
  precise vec3 q = closest_point_on_triangle(p - a, vec3(0.0), t.vertex[1].xyz - a, t.vertex[2].xyz - a,
                                             t.face_normal.xyz, feature) + a;
  pseudonormal = feature == FEATURE_FACE ? t.face_normal.xyz
                 : feature < FEATURE_VERTEX ? t.edge_normal[feature - FEATURE_EDGE].xyz
                                            : t.vertex_normal[feature - FEATURE_VERTEX].xyz;
  precise vec3 delta = p - q;
  return delta;
}

// The unsigned distance [voxels] from p to the triangle; always >= 0, so its bits order as uints.
float triangle_distance(vec3 p, SdfTriangle t) {
  vec3 pseudonormal;
  precise float d = length(triangle_delta(p, t, pseudonormal));
  return d;
}

// xyz: unit gradient of the signed distance (from the closest point towards p, flipped inside);
// w: signed distance [voxels], |w| == triangle_distance(p, t).
vec4 voxel_value(vec3 p, SdfTriangle t) {
  vec3 pseudonormal;
  vec3 delta = triangle_delta(p, t, pseudonormal);
  precise float d = length(delta);
  float s = dot(delta, pseudonormal) >= 0.0 ? 1.0 : -1.0;
  vec3 gradient = d > 1e-6 ? s * delta / d : pseudonormal;
  return vec4(gradient, s * d);
}

#endif
