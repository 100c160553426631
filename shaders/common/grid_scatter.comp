#version 450
// Counting sort, pass 3: particle ids into their cell's range of the sorted array.
layout(local_size_x = 256) in;
layout(std430, binding = 1) readonly buffer CellOf { uint cell_of[]; };
layout(std430, binding = 3) readonly buffer Slot { uint slot[]; };
layout(std430, binding = 4) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 5) writeonly buffer Sorted { uint sorted_ids[]; };
uniform uint count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < count) sorted_ids[cell_start[cell_of[i]] + slot[i]] = i;
}
