#version 450
#extension GL_GOOGLE_include_directive : require
// destination[0, count) = source[0, count). A kernel rather than glCopyNamedBufferSubData so that, in
// a section of GPU-decided work (gpu::Queue::begin_indirect), the copy runs only when the rest does.
#include "common/dispatch.glsl"
#include "common/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_COPY_SOURCE) readonly buffer Source { uint source[]; };
layout(std430, binding = TS_COPY_DESTINATION) writeonly buffer Destination { uint destination[]; };
#include "common/params.h"
layout(std140, binding = TS_FILL_PARAMS) uniform FillBlock { ItemCount params; };
void main() {
  uint i = dispatch_item();
  if (i < params.count.x) destination[i] = source[i];
}
