// Keyframed kinematic bodies, the GLSL twin of sim::sample_track (sim/keyframes.cpp): straight-line
// motion of the centre of mass at constant velocity between keys, slerp of the orientation at a
// constant angular velocity (the shorter way round); the first pose held before the first key and
// the last after the last, at rest.
#ifndef TETRASAND_SIM_KEYFRAMES_GLSL
#define TETRASAND_SIM_KEYFRAMES_GLSL
#include "sim/precision.glsl"

struct KinematicState {
  real3 position, velocity, omega;  // [m], [m/s], [rad/s]
  real4 orientation;                // (x, y, z, w)
};

// Quaternion product a * b, (x, y, z, w) storage.
real4 quaternion_product(real4 a, real4 b) {
  return real4(a.w * b.xyz + b.w * a.xyz + cross(a.xyz, b.xyz), a.w * b.w - dot(a.xyz, b.xyz));
}

// The including shader declares the track buffer `keyframes` (binding TS_SIM_KEYFRAMES) first:
// position and time at [2k], orientation at [2k + 1]; the track is `count` keys from `first`.
KinematicState sample_track(uint first, uint count, real time) {
  KinematicState state;
  state.velocity = real3(0.0);
  state.omega = real3(0.0);
  uint last_key = first + count - 1u;
  if (time < keyframes[2u * first].w || time >= keyframes[2u * last_key].w || count == 1u) {
    uint hold = time < keyframes[2u * first].w ? first : last_key;
    state.position = keyframes[2u * hold].xyz;
    state.orientation = keyframes[2u * hold + 1u];
    return state;
  }
  uint a = first;  // the segment [a, a + 1) holding `time`
  while (keyframes[2u * (a + 1u)].w <= time) ++a;
  real4 pa = keyframes[2u * a], pb = keyframes[2u * a + 2u];
  real4 qa = keyframes[2u * a + 1u], qb = keyframes[2u * a + 3u];
  real span = pb.w - pa.w;  // [s]
  real u = (time - pa.w) / span;
  state.velocity = (pb.xyz - pa.xyz) / span;
  state.position = pa.xyz + u * (pb.xyz - pa.xyz);
  // The world-frame turn from a to b, the shorter way: angle theta about `axis` (trigonometry in
  // float, which GLSL's double lacks).
  real4 turn = quaternion_product(qb, real4(-qa.xyz, qa.w));
  if (turn.w < 0.0) turn = -turn;
  real s = length(turn.xyz);
  real theta = 2.0 * real(atan(float(s), float(turn.w)));
  real3 axis = s > 0.0 ? turn.xyz / s : real3(0.0, 0.0, 1.0);
  state.omega = axis * (theta / span);
  real half_angle = 0.5 * u * theta;
  real4 partial = real4(axis * real(sin(float(half_angle))), real(cos(float(half_angle))));
  real4 q = quaternion_product(partial, qa);
  state.orientation = q / length(q);
  return state;
}
#endif
