#version 450
#extension GL_GOOGLE_include_directive : require
// Exclusive prefix sum, pass 1: each work group scans 512 values in shared memory (Blelloch 1990) and
// writes its total to block_sums, which the host scans recursively before scan_add.comp adds it back.
#include "common/dispatch.glsl"
#include "common/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SCAN_VALUES) buffer Values { uint values[]; };
layout(std430, binding = TS_SCAN_BLOCK_SUMS) writeonly buffer BlockSums { uint block_sums[]; };
#include "common/params.h"
layout(std140, binding = TS_SCAN_PARAMS) uniform ScanBlock { ItemCount params; };
shared uint temp[512];
void main() {
  uint t = gl_LocalInvocationID.x;
  uint base = dispatch_group() * 512u;
  if (base >= params.count.x) return;  // a group past the end (2D layout): no block, no block sum
  temp[2u * t] = base + 2u * t < params.count.x ? values[base + 2u * t] : 0u;
  temp[2u * t + 1u] = base + 2u * t + 1u < params.count.x ? values[base + 2u * t + 1u] : 0u;
  uint offset = 1u;
  for (uint d = 256u; d > 0u; d >>= 1u) {
    barrier();
    if (t < d) {
      uint ai = offset * (2u * t + 1u) - 1u, bi = offset * (2u * t + 2u) - 1u;
      temp[bi] += temp[ai];
    }
    offset <<= 1u;
  }
  if (t == 0u) {
    block_sums[dispatch_group()] = temp[511];
    temp[511] = 0u;
  }
  for (uint d = 1u; d < 512u; d <<= 1u) {
    offset >>= 1u;
    barrier();
    if (t < d) {
      uint ai = offset * (2u * t + 1u) - 1u, bi = offset * (2u * t + 2u) - 1u;
      uint x = temp[ai];
      temp[ai] = temp[bi];
      temp[bi] += x;
    }
  }
  barrier();
  if (base + 2u * t < params.count.x) values[base + 2u * t] = temp[2u * t];
  if (base + 2u * t + 1u < params.count.x) values[base + 2u * t + 1u] = temp[2u * t + 1u];
}
