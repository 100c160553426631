// Hashed uniform grid shared by the sampler and the simulator: memory proportional to the number of
// particles (table size ~2x particles), not to the domain, and no cap on particles per cell.
#ifndef TETRASAND_COMMON_HASH_GRID_GLSL
#define TETRASAND_COMMON_HASH_GRID_GLSL

ivec3 cell_of_position(vec3 p, float cell_size) { return ivec3(floor(p / cell_size)); }

// Teschner et al. 2003 spatial hash; table_size is a power of two.
uint hash_cell(ivec3 c, uint table_size) {
  uint h = (uint(c.x) * 73856093u) ^ (uint(c.y) * 19349663u) ^ (uint(c.z) * 83492791u);
  return h & (table_size - 1u);
}

#endif
