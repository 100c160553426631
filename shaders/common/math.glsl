// Small numeric helpers shared by kernels.
#ifndef TETRASAND_COMMON_MATH_GLSL
#define TETRASAND_COMMON_MATH_GLSL

const float TS_PI = 3.14159265358979323846;

// Rotate v by the unit quaternion q = (x, y, z, w).
vec3 quat_rotate(vec4 q, vec3 v) {
  vec3 t = 2.0 * cross(q.xyz, v);
  return v + q.w * t + cross(q.xyz, t);
}

uint ceil_div(uint a, uint b) { return (a + b - 1u) / b; }

#endif
