// Rigid-body helpers: quaternions (x, y, z, w) and the world-frame inverse inertia R I0^-1 R^T.
#ifndef TETRASAND_SIM_RIGID_GLSL
#define TETRASAND_SIM_RIGID_GLSL
#include "sim/precision.glsl"

real3 rotate(real4 q, real3 v) {
  real3 t = 2.0 * cross(q.xyz, v);
  return v + q.w * t + cross(q.xyz, t);
}

real3 rotate_inverse(real4 q, real3 v) { return rotate(real4(-q.xyz, q.w), v); }

// R I0^-1 R^T applied to a world-frame vector; I0^-1 given by its rows (body frame).
real3 apply_world_inverse_inertia(real4 q, real3 row0, real3 row1, real3 row2, real3 world_vector) {
  real3 local = rotate_inverse(q, world_vector);
  return rotate(q, real3(dot(row0, local), dot(row1, local), dot(row2, local)));
}

// q(t + dt) = q + dt/2 [omega, 0] q, renormalised (thesis eqs. 3.47-3.50).
real4 integrate_orientation(real4 q, real3 omega, real dt) {
  real4 w = real4(omega, 0.0);
  // Quaternion product w * q with (x, y, z, w) storage.
  real4 wq = real4(w.w * q.xyz + q.w * w.xyz + cross(w.xyz, q.xyz), w.w * q.w - dot(w.xyz, q.xyz));
  real4 r = q + 0.5 * dt * wq;
  return r / length(r);
}
#endif
