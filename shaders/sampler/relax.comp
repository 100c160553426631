#version 450
#extension GL_GOOGLE_include_directive : require
// One relaxation step of the repulsion sampler (thesis 6.3; Witkin & Heckbert 1994; Bell et al. 2005):
// each particle moves by -phi grad(phi) (to the zero level set) plus Gaussian repulsion from the
// neighbours in the 27 surrounding cells, projected onto the tangent plane so that repulsion spreads
// particles over the surface instead of pushing them off it. Positions ping-pong between two buffers.
#include "common/hash_grid.glsl"
#include "sampler/sdf_sample.glsl"

layout(local_size_x = 128) in;
layout(std430, binding = 0) readonly buffer PositionsIn { vec4 p_in[]; };
layout(std430, binding = 1) writeonly buffer PositionsOut { vec4 p_out[]; };
layout(std430, binding = 2) readonly buffer CellCount { uint cell_count[]; };
layout(std430, binding = 4) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 5) readonly buffer Sorted { uint sorted_ids[]; };
layout(std430, binding = 6) writeonly buffer StepInfo { vec4 step_info[]; };  // x: |move| [m], y: |phi| [m], z: 1 if outside the band

uniform uint count;
uniform float cell_size;       // = repulsion cutoff [m]
uniform uint table_size;
uniform float inv_two_sigma2;  // 1 / (2 sigma^2) [1/m^2]
uniform float repulsion_gain;  // dimensionless step on the kernel sum
uniform float max_move;        // CFL guard: at most this far per step [m]
uniform float band_limit;      // |phi| beyond which a particle has left the band [m]

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec3 p = p_in[i].xyz;
  vec4 s = sample_sdf(p);
  vec3 n = s.xyz;
  float phi = s.w;

  ivec3 c = cell_of_position(p, cell_size);
  float cutoff2 = cell_size * cell_size;
  vec3 repulsion = vec3(0.0);
  uint visited[27];
  int visited_count = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        uint h = hash_cell(c + ivec3(dx, dy, dz), table_size);
        // Two neighbour cells may share a hash bucket: visit each bucket once.
        bool seen = false;
        for (int v = 0; v < visited_count; ++v) seen = seen || visited[v] == h;
        if (seen) continue;
        visited[visited_count++] = h;
        uint begin = cell_start[h], end = begin + cell_count[h];
        for (uint k = begin; k < end; ++k) {
          uint j = sorted_ids[k];
          if (j == i) continue;
          vec3 x = p - p_in[j].xyz;
          float d2 = dot(x, x);
          if (d2 < cutoff2) repulsion += exp(-d2 * inv_two_sigma2) * x;
        }
      }
  repulsion -= dot(repulsion, n) * n;
  vec3 move = repulsion_gain * repulsion - phi * n;
  float length_move = length(move);
  if (length_move > max_move) move *= max_move / length_move;
  p_out[i] = vec4(p + move, 0.0);
  step_info[i] = vec4(min(length_move, max_move), abs(phi), abs(phi) >= band_limit ? 1.0 : 0.0, 0.0);
}
