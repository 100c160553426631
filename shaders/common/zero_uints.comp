#version 450
#extension GL_GOOGLE_include_directive : require
// values[0, count) = 0. A kernel rather than glClearNamedBufferData so that, in a section of
// GPU-decided work (gpu::Queue::begin_indirect), the clear runs only when the rest does.
#include "common/dispatch.glsl"
#include "common/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_FILL_VALUES) writeonly buffer Values { uint values[]; };
#include "common/params.h"
layout(std140, binding = TS_FILL_PARAMS) uniform FillBlock { ItemCount params; };
void main() {
  uint i = dispatch_item();
  if (i < params.count.x) values[i] = 0u;
}
