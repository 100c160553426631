#version 450
#extension GL_GOOGLE_include_directive : require
// Steps 4 and 5, per body: sum its particles' forces and torques in particle order (deterministic),
// then integrate, mirroring CpuStepper::integrate (sim/cpu_stepper.cpp). Rotation first (thesis eqs.
// 3.47-3.50) through the angular momentum L, omega = R I0^-1 R^T L; forward Euler moves with the old
// velocities, semi-implicit Euler with the new ones. Static bodies are skipped; kinematic bodies
// follow their prescribed velocities or
// their keyframes (sim/keyframes.glsl). Velocity clamps (thesis 3.3.1) are counted, never silent.
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "common/layouts.h"
#include "sim/rigid.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = TS_SIM_BODY_POSITION) buffer BP { real4 body_position[]; };
layout(std430, binding = TS_SIM_BODY_ORIENTATION) buffer BQ { real4 body_orientation[]; };
layout(std430, binding = TS_SIM_BODY_VELOCITY) buffer BV { real4 body_velocity[]; };
layout(std430, binding = TS_SIM_BODY_OMEGA) buffer BW { real4 body_omega[]; };
layout(std430, binding = TS_SIM_BODY_INV_INERTIA) readonly buffer BI { real4 body_inverse_inertia[]; };
layout(std430, binding = TS_SIM_BODY_RANGE) readonly buffer BR { uvec4 body_range[]; };
layout(std430, binding = TS_SIM_PARTICLE_WRENCH) readonly buffer F { real4 particle_wrench[]; };
layout(std430, binding = TS_SIM_COUNTERS) buffer C { uint counters[]; };
layout(std430, binding = TS_SIM_BODY_MOMENTUM) buffer BL { real4 body_momentum[]; };
layout(std430, binding = TS_SIM_KEYFRAMES) readonly buffer K { real4 keyframes[]; };
#include "sim/keyframes.glsl"

#include "common/params.h"
#ifdef TS_FP64
layout(std140, binding = TS_SIM_PARAMS) uniform IntegrateBlock { SimIntegrateParams64 params; };
#else
layout(std140, binding = TS_SIM_PARAMS) uniform IntegrateBlock { SimIntegrateParams params; };
#endif

void main() {
  uint b = dispatch_item();
  if (b >= params.sizes.x) return;
  uint motion = uint(max(body_velocity[b].w, 0.0));  // a motion type (0-2); clamped: a negative float to uint is undefined
  if (motion == TS_MOTION_STATIC) return;
  real h = params.gravity_dt.w;
  real4 q = body_orientation[b];
  if (motion == TS_MOTION_KINEMATIC && body_range[b].w > 0u) {
    KinematicState state = sample_track(body_range[b].z, body_range[b].w, params.time.x);
    body_position[b].xyz = state.position;
    body_orientation[b] = state.orientation;
    body_velocity[b].xyz = state.velocity;
    body_omega[b].xyz = state.omega;
    return;
  }
  if (motion == TS_MOTION_KINEMATIC) {
    body_position[b].xyz += h * body_velocity[b].xyz;
    body_orientation[b] = integrate_orientation(q, body_omega[b].xyz, h);
    return;
  }
  real3 force = real3(0.0), torque = real3(0.0);
  uint first = body_range[b].x, count = body_range[b].y;
  for (uint k = first; k < first + count; ++k) {
    force += particle_wrench[2u * k].xyz;
    torque += particle_wrench[2u * k + 1u].xyz;
  }
  real3 row0 = body_inverse_inertia[3u * b].xyz, row1 = body_inverse_inertia[3u * b + 1u].xyz,
        row2 = body_inverse_inertia[3u * b + 2u].xyz;
  real reach = body_inverse_inertia[3u * b].w;
  real3 acceleration = params.gravity_dt.xyz + body_position[b].w * force;
  real3 momentum = body_momentum[b].xyz + torque * h;
  real3 w_move = params.models.x != 0 ? apply_world_inverse_inertia(q, row0, row1, row2, momentum) : body_omega[b].xyz;
  real4 q_new = integrate_orientation(q, w_move, h);
  real3 w = apply_world_inverse_inertia(q_new, row0, row1, row2, momentum);
  real3 v = body_velocity[b].xyz + acceleration * h;
  body_position[b].xyz += (params.models.x != 0 ? v : body_velocity[b].xyz) * h;

  real limit = real(params.limits.x);
  if (length(v) > limit) {
    v *= limit / length(v);
    atomicAdd(counters[0], 1u);
  }
  if (length(w) * reach > limit) {
    real factor = limit / (length(w) * reach);
    w *= factor;
    momentum *= factor;  // omega is linear in L
    atomicAdd(counters[1], 1u);
  }
  if (params.limits.y > 0.0 && length(v) + length(w) * reach < real(params.limits.z)) {
    real factor = max(real(0.0), 1.0 - real(params.limits.y) * h);
    w *= factor;
    momentum *= factor;
  }
  body_orientation[b] = q_new;
  body_velocity[b].xyz = v;
  body_omega[b].xyz = w;
  body_momentum[b].xyz = momentum;
}
