#version 450
#extension GL_GOOGLE_include_directive : require
// Ray casting, vertex stage (thesis 6.4, "enhanced GPU algorithm"): the SDF's bounding box is
// rasterised, so only pixels whose ray meets the box run the fragment stage. 36 vertices from
// gl_VertexID; with front faces culled each covered pixel gets exactly one fragment, on the far
// face, also when the eye is inside the box.
#include "preview/camera.glsl"
#include "preview/volume.glsl"

out vec3 v_world;  // relative world [m]

// Corner c = x + 2y + 4z; triangles counter-clockwise seen from outside.
const int kCube[36] = int[](0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                            2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6);

void main() {
  int c = kCube[gl_VertexID];
  vec3 corner = vec3(float(c & 1), float((c >> 1) & 1), float((c >> 2) & 1));
  v_world = volume.origin_voxel.xyz + volume.origin_voxel.w * corner * (volume.dims_band.xyz - 1.0);
  gl_Position = camera.view_projection * vec4(v_world, 1.0);
}
