#version 450
#extension GL_GOOGLE_include_directive : require
// Coverage certificate, after one level is evaluated and its split and uncovered flags scanned
// (exclusive prefix sums over count + 1 entries, so entry e's own flag is scan[e + 1] - scan[e]):
// each split sub-triangle writes its four children to the next level's queue at its scanned offset,
// each final uncovered one itself and its bounds to the holes. Offsets come from the scan, not from
// atomics, so the next queue and the holes are in the same order on every run.
#include "common/dispatch.glsl"
#include "common/bindings.h"
#include "common/layouts.h"
#include "sampler/bindings.h"

layout(local_size_x = 64) in;
layout(std430, binding = TS_CERT_QUEUE) readonly buffer Queue { uvec4 queue[]; };
layout(std430, binding = TS_CERT_SPLITS) readonly buffer SplitOffsets { uint split_offset[]; };
layout(std430, binding = TS_CERT_UNCOVERED) readonly buffer HoleOffsets { uint hole_offset[]; };
layout(std430, binding = TS_CERT_BOUNDS) readonly buffer Bounds { vec4 bounds[]; };
layout(std430, binding = TS_CERT_NEXT_QUEUE) writeonly buffer NextQueue { uvec4 next_queue[]; };
layout(std430, binding = TS_CERT_HOLES) writeonly buffer Holes { CertLeaf holes[]; };

#include "common/params.h"
layout(std140, binding = TS_SAMPLER_PARAMS) uniform ScatterBlock { ItemCount params; };

uvec4 child(uint triangle, uint level, bool down, uint i, uint j) {
  return uvec4(triangle, level | (down ? 1u << 8 : 0u), i, j);
}

void main() {
  uint e = dispatch_item();
  if (e >= params.count.x) return;
  uvec4 id = queue[e];
  uint first = split_offset[e];
  if (split_offset[e + 1u] > first) {
    // The midpoint split on the level + 1 grid: an up (i, j) holds the ups (2i, 2j), (2i+1, 2j),
    // (2i, 2j+1) and the down (2i, 2j); a down (i, j) the downs (2i+1, 2j), (2i, 2j+1),
    // (2i+1, 2j+1) and the up (2i+1, 2j+1).
    uint level = (id.y & 0xffu) + 1u;
    bool down = (id.y >> 8) != 0u;
    uint i = 2u * id.z, j = 2u * id.w;
    if (!down) {
      next_queue[first] = child(id.x, level, false, i, j);
      next_queue[first + 1u] = child(id.x, level, false, i + 1u, j);
      next_queue[first + 2u] = child(id.x, level, false, i, j + 1u);
      next_queue[first + 3u] = child(id.x, level, true, i, j);
    } else {
      next_queue[first] = child(id.x, level, true, i + 1u, j);
      next_queue[first + 1u] = child(id.x, level, true, i, j + 1u);
      next_queue[first + 2u] = child(id.x, level, true, i + 1u, j + 1u);
      next_queue[first + 3u] = child(id.x, level, false, i + 1u, j + 1u);
    }
  }
  uint hole = hole_offset[e];
  if (hole_offset[e + 1u] > hole) holes[hole] = CertLeaf(id, bounds[e]);
}
