#version 450
#extension GL_GOOGLE_include_directive : require
// Scan conversion, fragment stage: the exact distance from this voxel's centre to this fragment's
// triangle, signed by the pseudonormal of the closest feature (sdf/voxel_value.glsl, shared with the
// compute path). The depth test (GL_LESS on |d|) keeps, per voxel, the triangle nearest to it, over
// all triangles and all geometry-shader invocations.
#include "common/layouts.h"
#include "sdf/bindings.h"

layout(std430, binding = TS_SDF_TRIANGLES) readonly buffer Triangles { SdfTriangle triangles[]; };

#include "common/params.h"
#include "sdf/voxel_value.glsl"
layout(std140, binding = TS_SDF_SCAN_PARAMS) uniform ScanConvertBlock { ScanConvertParams params; };

flat in uint g_triangle;
// xyz: unit gradient of the signed distance (from the closest point towards the voxel, flipped
// inside); w: signed distance [voxels].
layout(location = 0) out vec4 value;

void main() {
  // Voxel centres sit at integer voxel coordinates, pixel centres at +0.5.
  vec3 p = vec3(gl_FragCoord.xy - 0.5, float(params.layers.x + gl_Layer));
  vec4 v = voxel_value(p, triangles[g_triangle]);
  float d = abs(v.w);
  if (d >= params.grid.z) discard;
  gl_FragDepth = d / params.grid.z;
  value = v;
}
