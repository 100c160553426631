#version 450
#extension GL_GOOGLE_include_directive : require
// One relaxation step of the repulsion sampler (thesis 6.3; Witkin & Heckbert 1994; Bell et al. 2005):
// each particle moves by -phi grad(phi) (to the zero level set) plus Gaussian repulsion from the
// neighbours in the 27 surrounding cells, projected onto the tangent plane so that repulsion spreads
// particles over the surface instead of pushing them off it.
//
// The tangential part is gradient descent on the repulsion energy with heavy-ball momentum (Polyak
// 1964): v <- beta v + gain F_t, kept tangential. Plain descent crawls on the long-wavelength modes of
// a large arrangement (their stiffness falls like (spacing / wavelength)^2); momentum speeds them up by
// 1 / (1 - beta) while the stiff short modes stay stable (gain * stiffness < 2 (1 + beta)). The
// attraction -phi n is not accumulated, so nothing overshoots across the surface.
//
// positions.w = 1 marks a mobile particle; 0 a frozen one, which still repels but does not move (the
// local re-relaxation after an injection moves only the particles near the new ones).
#include "common/dispatch.glsl"
#include "common/hash_grid.glsl"
#include "common/bindings.h"
#include "sampler/bindings.h"
#include "sampler/sdf_sample.glsl"

layout(local_size_x = 128) in;
layout(std430, binding = TS_SAMPLER_POSITIONS_IN) readonly buffer PositionsIn { vec4 p_in[]; };
layout(std430, binding = TS_SAMPLER_POSITIONS_OUT) writeonly buffer PositionsOut { vec4 p_out[]; };
layout(std430, binding = TS_GRID_CELL_COUNT) readonly buffer CellCount { uint cell_count[]; };
layout(std430, binding = TS_SAMPLER_VELOCITIES) buffer Velocities { vec4 velocity[]; };  // xyz: momentum step [m], own entry only
layout(std430, binding = TS_GRID_CELL_START) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = TS_GRID_SORTED) readonly buffer Sorted { uint sorted_ids[]; };
// x: |tangential gradient step| [m] (the residual; 0 if frozen; the normal term is left out because it
// measures the distance to the surface, not the arrangement, and the exact projection fixes the normal
// position afterwards), y: |phi| [m], z: 1 if outside the band, w: 1 if mobile
layout(std430, binding = TS_SAMPLER_STEP_INFO) writeonly buffer StepInfo { vec4 step_info[]; };

#include "common/params.h"
layout(std140, binding = TS_SAMPLER_PARAMS) uniform RelaxBlock { RelaxParams params; };

vec3 repulsion_at(uint i, vec3 p) {
  ivec3 c = cell_of_position(p, params.kernel.x);
  float cutoff2 = params.kernel.x * params.kernel.x;
  vec3 repulsion = vec3(0.0);
  uint visited[27];
  int visited_count = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        uint h = hash_cell(c + ivec3(dx, dy, dz), params.sizes.y);
        // Two neighbour cells may share a hash bucket: visit each bucket once.
        bool seen = false;
        // ts-audit: allow uninitialised-read (only entries below visited_count, each written before)
        for (int v = 0; v < visited_count; ++v) seen = seen || visited[v] == h;
        if (seen) continue;
        visited[visited_count++] = h;
        uint begin = cell_start[h], end = begin + cell_count[h];
        for (uint k = begin; k < end; ++k) {
          uint j = sorted_ids[k];
          if (j == i) continue;
          vec3 x = p - p_in[j].xyz;
          float d2 = dot(x, x);
          // Coincident particles feel no Gaussian force (x = 0): part them along a fixed axis, the
          // lower id one way and the higher the other; the tangential projection below keeps it on the surface.
          if (d2 == 0.0) x = (i < j ? 1e-3 : -1e-3) * params.kernel.x * vec3(0.6, 0.48, 0.64);
          if (d2 < cutoff2) repulsion += exp(-d2 * params.kernel.y) * x;
        }
      }
  return repulsion;
}

void main() {
  uint i = dispatch_item();
  if (i >= params.sizes.x) return;
  vec4 pw = p_in[i];
  vec3 p = pw.xyz;
  vec4 s = sample_sdf(p);
  vec3 n = s.xyz;
  float phi = s.w;
  bool outside = abs(phi) >= params.limits.y;
  if (pw.w == 0.0) {
    p_out[i] = pw;
    step_info[i] = vec4(0.0, abs(phi), outside ? 1.0 : 0.0, 0.0);
    return;
  }
  vec3 f = repulsion_at(i, p);
  f = params.kernel.z * (f - dot(f, n) * n);
  // Adaptive restart (O'Donoghue & Candes 2015, per particle): momentum that points against the
  // force is dropped. Without it a particle that flips sides of a feature thinner than a voxel (the
  // tangent plane turning over from step to step) or one squeezed against frozen neighbours rings
  // instead of settling.
  vec3 v_old = velocity[i].xyz;
  vec3 v = (dot(v_old, f) > 0.0 ? params.kernel.w * v_old : vec3(0.0)) + f;
  v -= dot(v, n) * n;
  vec3 move = v - phi * n;
  float length_move = length(move);
  if (length_move > params.limits.x) {
    move *= params.limits.x / length_move;
    v *= params.limits.x / length_move;
  }
  velocity[i] = vec4(v, 0.0);
  p_out[i] = vec4(p + move, 1.0);
  step_info[i] = vec4(length(f), abs(phi), outside ? 1.0 : 0.0, 1.0);
}
