// The camera every preview pass shares. World positions are relative to the scene centre [m], so
// float precision does not depend on where the scene sits.
#ifndef TETRASAND_PREVIEW_CAMERA_GLSL
#define TETRASAND_PREVIEW_CAMERA_GLSL

#include "common/params.h"
#include "preview/bindings.h"
layout(std140, binding = TS_PREVIEW_CAMERA) uniform CameraBlock { CameraParams camera; };

// Direction of the camera ray through the world point q.
vec3 ray_direction(vec3 q) { return camera.lens.x == 1 ? camera.forward.xyz : normalize(q - camera.eye.xyz); }

// Window depth (0 near .. 1 far) of a world point.
float window_depth(vec3 p) {
  vec4 c = camera.view_projection * vec4(p, 1.0);
  return 0.5 * c.z / c.w + 0.5;
}

// The world point seen at window position (pixel coordinates, depth 0..1).
vec3 world_from_window(vec2 window, float depth) {
  vec4 w = camera.inverse_view_projection * vec4(2.0 * window / camera.viewport.xy - 1.0, 2.0 * depth - 1.0, 1.0);
  return w.xyz / w.w;
}

#endif
