#version 450
#extension GL_GOOGLE_include_directive : require
// One colour on every fragment: the smallest fragment stage, used by tests of the GPU layer's draws.
#include "common/params.h"
#include "test/bindings.h"
layout(std140, binding = TS_TEST_PARAMS) uniform SolidColorBlock { SolidColorParams params; };

layout(location = 0) out vec4 fragment;

void main() { fragment = params.color; }
