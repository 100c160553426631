// The camera every preview pass shares. World positions are relative to the scene centre [m], so
// float precision does not depend on where the scene sits.
#ifndef TETRASAND_PREVIEW_CAMERA_GLSL
#define TETRASAND_PREVIEW_CAMERA_GLSL

uniform mat4 view_projection;          // world -> clip (depth -1..1)
uniform mat4 inverse_view_projection;  // clip -> world
uniform vec3 eye;                      // pinhole position (perspective lens)
uniform vec3 view_forward;             // unit, the camera's forward axis
uniform vec3 view_right;               // unit
uniform vec3 view_up;                  // unit, the image's up axis
uniform int orthographic;              // 1: parallel rays along view_forward
uniform vec2 viewport;                 // [pixels]

// Direction of the camera ray through the world point q.
vec3 ray_direction(vec3 q) { return orthographic == 1 ? view_forward : normalize(q - eye); }

// Window depth (0 near .. 1 far) of a world point.
float window_depth(vec3 p) {
  vec4 c = view_projection * vec4(p, 1.0);
  return 0.5 * c.z / c.w + 0.5;
}

// The world point seen at window position (pixel coordinates, depth 0..1).
vec3 world_from_window(vec2 window, float depth) {
  vec4 w = inverse_view_projection * vec4(2.0 * window / viewport - 1.0, 2.0 * depth - 1.0, 1.0);
  return w.xyz / w.w;
}

#endif
