#version 450
#extension GL_GOOGLE_include_directive : require
// Scan conversion, fragment stage: the exact distance from this voxel's centre to this fragment's
// triangle, signed by the pseudonormal of the closest feature. The depth test (GL_LESS on |d|) keeps,
// per voxel, the triangle nearest to it, over all triangles and all geometry-shader invocations.
#include "common/layouts.h"
#include "sdf/bindings.h"
#include "sdf/closest_point.glsl"

layout(std430, binding = TS_SDF_TRIANGLES) readonly buffer Triangles { SdfTriangle triangles[]; };

#include "common/params.h"
layout(std140, binding = TS_SDF_SCAN_PARAMS) uniform ScanConvertBlock { ScanConvertParams params; };

flat in uint g_triangle;
// xyz: unit gradient of the signed distance (from the closest point towards the voxel, flipped
// inside); w: signed distance [voxels].
layout(location = 0) out vec4 value;

void main() {
  // Voxel centres sit at integer voxel coordinates, pixel centres at +0.5.
  vec3 p = vec3(gl_FragCoord.xy - 0.5, float(params.layers.x + gl_Layer));
  SdfTriangle t = triangles[g_triangle];
  int feature;
  // Work relative to vertex 0 so the error does not grow with the grid coordinate.
  vec3 a = t.vertex[0].xyz;
  vec3 q = closest_point_on_triangle(p - a, vec3(0.0), t.vertex[1].xyz - a, t.vertex[2].xyz - a,
                                     t.face_normal.xyz, feature) + a;
  vec3 pseudonormal = feature == FEATURE_FACE ? t.face_normal.xyz
                      : feature < FEATURE_VERTEX ? t.edge_normal[feature - FEATURE_EDGE].xyz
                                                 : t.vertex_normal[feature - FEATURE_VERTEX].xyz;
  vec3 delta = p - q;
  float d = length(delta);
  if (d >= params.grid.z) discard;
  float s = dot(delta, pseudonormal) >= 0.0 ? 1.0 : -1.0;
  vec3 gradient = d > 1e-6 ? s * delta / d : pseudonormal;
  gl_FragDepth = d / params.grid.z;
  value = vec4(gradient, s * d);
}
