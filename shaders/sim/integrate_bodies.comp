#version 450
#extension GL_GOOGLE_include_directive : require
// Steps 4 and 5: per-body sum of its particles' forces and torques (in particle order: deterministic),
// then integration. Forward Euler as the thesis (eqs. 3.44-3.50: rotation before translation, angular
// momentum L updated and omega = R I0^-1 R^T L) or semi-implicit Euler (velocities first). Static
// bodies are skipped; kinematic bodies follow their prescribed velocities.
#include "common/layouts.h"
#include "sim/rigid.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = TS_SIM_BODY_POSITION) buffer BP { real4 body_position[]; };
layout(std430, binding = TS_SIM_BODY_ORIENTATION) buffer BQ { real4 body_orientation[]; };
layout(std430, binding = TS_SIM_BODY_VELOCITY) buffer BV { real4 body_velocity[]; };
layout(std430, binding = TS_SIM_BODY_OMEGA) buffer BW { real4 body_omega[]; };
layout(std430, binding = TS_SIM_BODY_INV_INERTIA) readonly buffer BI { real4 body_inverse_inertia[]; };
layout(std430, binding = TS_SIM_BODY_RANGE) readonly buffer BR { uvec4 body_range[]; };
layout(std430, binding = TS_SIM_PARTICLE_FORCE) readonly buffer F { real4 particle_force[]; };
layout(std430, binding = TS_SIM_PARTICLE_TORQUE) readonly buffer T { real4 particle_torque[]; };
layout(std430, binding = TS_SIM_COUNTERS) buffer C { uint counters[]; };
layout(std430, binding = TS_SIM_BODY_MOMENTUM) buffer BL { real4 body_momentum[]; };

uniform uint body_count;
uniform float dt;              // [s]
uniform vec3 gravity;          // [m/s^2]
uniform int semi_implicit;     // 0: forward Euler (thesis), 1: semi-implicit Euler
uniform float max_speed;       // velocity clamp [m/s] (thesis 3.3.1); every clamp is counted
uniform float angular_damping_speed;  // thesis pseudocode 4.4: below this |omega| [rad/s], damp; 0 = off
uniform float angular_damping_factor;

void main() {
  uint b = gl_GlobalInvocationID.x;
  if (b >= body_count) return;
  uint motion = uint(body_velocity[b].w);
  if (motion == TS_MOTION_STATIC) return;
  real4 q = body_orientation[b];
  real3 x = body_position[b].xyz;
  real3 v = body_velocity[b].xyz;
  real3 omega = body_omega[b].xyz;
  real h = real(dt);
  if (motion == TS_MOTION_KINEMATIC) {
    body_position[b].xyz = x + h * v;
    body_orientation[b] = integrate_orientation(q, omega, h);
    return;
  }
  real3 force = real3(0.0), torque = real3(0.0);
  uint first = body_range[b].x, count = body_range[b].y;
  for (uint k = first; k < first + count; ++k) {
    force += particle_force[k].xyz;
    torque += particle_torque[k].xyz;
  }
  real inverse_mass = body_position[b].w;
  force += real3(gravity) / inverse_mass;
  real3 inverse_principal = body_inverse_inertia[b].xyz;
  real3 momentum = body_momentum[b].xyz;

  real3 v_new = v + h * inverse_mass * force;
  real3 momentum_new = momentum + h * torque;
  real speed = length(v_new);
  if (speed > real(max_speed)) {
    v_new *= real(max_speed) / speed;
    atomicAdd(counters[0], 1u);
  }
  // Rotation before translation (thesis). Forward Euler moves with the old velocities.
  real3 omega_step = semi_implicit != 0 ? apply_world_inverse_inertia(q, inverse_principal, momentum_new) : omega;
  real3 v_step = semi_implicit != 0 ? v_new : v;
  real4 q_new = integrate_orientation(q, omega_step, h);
  real3 omega_new = apply_world_inverse_inertia(q_new, inverse_principal, momentum_new);
  if (angular_damping_speed > 0.0 && length(omega_new) < real(angular_damping_speed)) {
    omega_new *= real(angular_damping_factor);
    momentum_new = rotate(q_new, rotate_inverse(q_new, omega_new) / inverse_principal);
  }
  body_orientation[b] = q_new;
  body_position[b].xyz = x + h * v_step;
  body_velocity[b].xyz = v_new;
  body_omega[b].xyz = omega_new;
  body_momentum[b].xyz = momentum_new;
}
