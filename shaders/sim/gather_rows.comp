#version 450
// Re-sort, pass 4: dst row r = src row index[r], rows of `width` uvec4 words, copied bit for bit (so
// any per-body or per-particle array, float or double, moves with one kernel).
layout(local_size_x = 128) in;
layout(std430, binding = 1) readonly buffer Src { uvec4 src[]; };
layout(std430, binding = 2) writeonly buffer Dst { uvec4 dst[]; };
layout(std430, binding = 3) readonly buffer Index { uint index[]; };
uniform uint rows;
uniform uint width;
void main() {
  uint r = gl_GlobalInvocationID.x;
  if (r >= rows) return;
  uint from = index[r] * width, to = r * width;
  for (uint k = 0u; k < width; ++k) dst[to + k] = src[from + k];
}
