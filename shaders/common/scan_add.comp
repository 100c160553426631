#version 450
// Exclusive prefix sum, pass 2: adds each block's scanned offset to its 512 values.
layout(local_size_x = 256) in;
layout(std430, binding = 0) buffer Values { uint values[]; };
layout(std430, binding = 1) readonly buffer BlockOffsets { uint block_offsets[]; };
uniform uint count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < count) values[i] += block_offsets[i / 512u];
}
