// A leaf cell of the slab being turned into the GPU-resident leaf field (sdf/leaf_field.h): its
// place, and the grid voxel at a place inside it. The including kernel declares the LeafBuildParams
// block as `params` first.
#ifndef TETRASAND_SDF_LEAF_CELL_GLSL
#define TETRASAND_SDF_LEAF_CELL_GLSL

// Slab cell `c` (x fastest, then y, then leaf row): its cell coordinates, z counted from the slab's first row.
ivec3 slab_leaf_cell(uint c) {
  uint per_row = uint(params.leaves.x * params.leaves.y);
  return ivec3(int(c % uint(params.leaves.x)), int((c % per_row) / uint(params.leaves.x)), int(c / per_row));
}

// Voxel `v` of a leaf (x fastest: v = x + 8 y + 64 z, the values' order) of slab cell `cell`: its
// texel in the slab target (layer counted from the slab's first), and whether it lies in the grid.
ivec3 leaf_voxel_texel(ivec3 cell, uint v, out bool in_grid) {
  ivec3 texel = cell * 8 + ivec3(int(v & 7u), int((v >> 3u) & 7u), int(v >> 6u));
  in_grid = all(lessThan(texel + ivec3(0, 0, params.grid.w), params.grid.xyz));
  return texel;
}

#endif
