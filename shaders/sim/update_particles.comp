#version 450
#extension GL_GOOGLE_include_directive : require
// Step 1: body poses -> particle world positions and velocities (thesis eq. 3.43: v_p = v + w x (R o_p)),
// and the largest distance a particle has moved since the last list build, for list_decide.comp: a
// work group's maximum in shared memory, then one atomicMax on the float's bits (for floats >= 0 the
// bits order as the values; a NaN's bits exceed every number's, so a NaN forces a rebuild).
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "common/layouts.h"
#include "sim/rigid.glsl"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SIM_PARTICLE_POSITION) writeonly buffer P { vec4 particle_position[]; };
layout(std430, binding = TS_SIM_PARTICLE_VELOCITY) writeonly buffer V { real4 particle_velocity[]; };
layout(std430, binding = TS_SIM_PARTICLE_INFO) readonly buffer I { uvec4 particle_info[]; };
layout(std430, binding = TS_SIM_PARTICLE_LOCAL) readonly buffer L { real4 particle_local[]; };
layout(std430, binding = TS_SIM_BODY_POSITION) readonly buffer BP { real4 body_position[]; };
layout(std430, binding = TS_SIM_BODY_ORIENTATION) readonly buffer BQ { real4 body_orientation[]; };
layout(std430, binding = TS_SIM_BODY_VELOCITY) readonly buffer BV { real4 body_velocity[]; };
layout(std430, binding = TS_SIM_BODY_OMEGA) readonly buffer BW { real4 body_omega[]; };
layout(std430, binding = TS_SIM_BUILD_POSITION) readonly buffer B { vec4 build_position[]; };
layout(std430, binding = TS_SIM_LIST_STATE) buffer S { uint list_state[]; };
#ifdef TS_FP64
layout(std430, binding = TS_SIM_PARTICLE_POSITION_EXACT) writeonly buffer PX { dvec4 particle_position_exact[]; };
#endif
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform UpdateBlock { ItemCount params; };
shared uint group_moved;
void main() {
  if (gl_LocalInvocationIndex == 0u) group_moved = 0u;
  barrier();
  uint i = dispatch_item();
  if (i < params.count.x) {
    uint b = particle_info[i].x;
    real3 arm = rotate(body_orientation[b], particle_local[i].xyz);
    real3 x = body_position[b].xyz + arm;
    particle_position[i] = vec4(vec3(x), float(particle_local[i].w));
#ifdef TS_FP64
    particle_position_exact[i] = dvec4(x, particle_local[i].w);
#endif
    particle_velocity[i] = real4(body_velocity[b].xyz + cross(body_omega[b].xyz, arm), 0.0);
    atomicMax(group_moved, floatBitsToUint(distance(vec3(x), build_position[i].xyz)));
  }
  barrier();
  if (gl_LocalInvocationIndex == 0u) atomicMax(list_state[TS_SIM_LIST_MAX_DISPLACEMENT], group_moved);
}
