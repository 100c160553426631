#version 450
#extension GL_GOOGLE_include_directive : require
// Metrics for the CSV and the blow-up check, per work group (the host adds partials in order):
// x: translational kinetic energy [J], y: rotational kinetic energy [J], z: potential energy [J]
// relative to z = 0, w: NaN/inf count. Only dynamic bodies count.
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "common/layouts.h"
#include "sim/rigid.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SIM_BODY_POSITION) readonly buffer BP { real4 body_position[]; };
layout(std430, binding = TS_SIM_BODY_VELOCITY) readonly buffer BV { real4 body_velocity[]; };
layout(std430, binding = TS_SIM_BODY_OMEGA) readonly buffer BW { real4 body_omega[]; };
layout(std430, binding = TS_SIM_BODY_MOMENTUM) readonly buffer BL { real4 body_momentum[]; };
layout(std430, binding = TS_SIM_METRIC_PARTIALS) writeonly buffer Partials { dvec4 partials[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform MetricsBlock { SimMetricsParams params; };
shared dvec4 scratch[256];
void main() {
  uint b = dispatch_item(), t = gl_LocalInvocationID.x;
  if (dispatch_group() * gl_WorkGroupSize.x >= params.sizes.x) return;  // past the end: no partial
  dvec4 e = dvec4(0.0);
  if (b < params.sizes.x && uint(max(body_velocity[b].w, 0.0)) == TS_MOTION_DYNAMIC) {
    double m = 1.0 / double(body_position[b].w);
    dvec3 v = dvec3(body_velocity[b].xyz);
    e.x = 0.5 * m * dot(v, v);
    e.y = 0.5 * dot(dvec3(body_omega[b].xyz), dvec3(body_momentum[b].xyz));
    e.z = -m * dot(dvec3(params.gravity.xyz), dvec3(body_position[b].xyz));
    bool bad = any(isnan(body_position[b].xyz)) || any(isinf(body_position[b].xyz)) || any(isnan(body_velocity[b].xyz)) ||
               any(isinf(body_velocity[b].xyz)) || any(isnan(body_omega[b].xyz));
    e.w = bad ? 1.0 : 0.0;
  }
  scratch[t] = e;
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    barrier();
    if (t < stride) scratch[t] += scratch[t + stride];
  }
  if (t == 0u) partials[dispatch_group()] = scratch[0];
}
