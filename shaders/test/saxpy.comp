#version 450
#extension GL_GOOGLE_include_directive : require
// y <- a x + y: the smallest kernel, used by tests of the GPU layer (dispatch, barriers, readback, timers).
#include "common/dispatch.glsl"
#include "test/bindings.h"
layout(local_size_x = 64) in;
layout(std430, binding = TS_TEST_SAXPY_X) readonly buffer X { float x[]; };
layout(std430, binding = TS_TEST_SAXPY_Y) buffer Y { float y[]; };
#include "common/params.h"
layout(std140, binding = TS_TEST_PARAMS) uniform SaxpyBlock { SaxpyParams params; };
void main() {
  uint i = dispatch_item();
  if (i < params.count.x) y[i] = params.scale.x * x[i] + y[i];
}
