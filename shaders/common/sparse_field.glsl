// The narrow-band SDF as a sparse NanoVDB float level set (sdf::SparseField), read through NanoVDB's
// PNanoVDB.h (Debian libnanovdb-dev; copied beside the shaders by the build). The including kernel
// declares, before including this file, the grid's buffer at its own stage's binding slot: a
// readonly std430 block named SparseField holding `uint pnanovdb_buf_data[]` (see sampler/relax.comp).
// Positions are in grid-local voxel units (voxel (0,0,0) of the grid spec at 0), so float precision
// does not depend on where the grid sits in index space; values are world units.
#ifndef TETRASAND_COMMON_SPARSE_FIELD_GLSL
#define TETRASAND_COMMON_SPARSE_FIELD_GLSL

#include "common/params.h"
// Where the grid sits (sdf::SparseField::bind), at the uniform-block slot the kernel's stage names
// TS_FIELD_PARAMS (defined, like the chunk slots below, before this file is included).
layout(std140, binding = TS_FIELD_PARAMS) uniform FieldBlock { FieldParams field_params; };

// A grid larger than one storage block (llvmpipe's is 128 MiB) is uploaded in chunks of 2^TS_FIELD_CHUNK_SHIFT
// words, TS_FIELD_CHUNKS of them (sdf::SparseField::shader_defines; at most 8): chunk 0 is the block the
// kernel declares, chunk c > 0 is bound at TS_FIELD_CHUNK_<c>, a slot the kernel's stage header names.
// PNanoVDB then reads through the branch below (PNANOVDB_BUF_CUSTOM) instead of one array. Only the
// programs of a chunked grid are compiled with it: every PNanoVDB read inlines the branch, and a
// single-block grid keeps the plain read it had.
#if defined(TS_FIELD_CHUNKS) && TS_FIELD_CHUNKS > 1
#if TS_FIELD_CHUNKS > 8
#error "sdf::SparseField uploads at most 8 chunks"
#endif
layout(std430, binding = TS_FIELD_CHUNK_1) readonly buffer SparseFieldChunk1 { uint field_chunk1[]; };
#if TS_FIELD_CHUNKS > 2
layout(std430, binding = TS_FIELD_CHUNK_2) readonly buffer SparseFieldChunk2 { uint field_chunk2[]; };
#endif
#if TS_FIELD_CHUNKS > 3
layout(std430, binding = TS_FIELD_CHUNK_3) readonly buffer SparseFieldChunk3 { uint field_chunk3[]; };
#endif
#if TS_FIELD_CHUNKS > 4
layout(std430, binding = TS_FIELD_CHUNK_4) readonly buffer SparseFieldChunk4 { uint field_chunk4[]; };
#endif
#if TS_FIELD_CHUNKS > 5
layout(std430, binding = TS_FIELD_CHUNK_5) readonly buffer SparseFieldChunk5 { uint field_chunk5[]; };
#endif
#if TS_FIELD_CHUNKS > 6
layout(std430, binding = TS_FIELD_CHUNK_6) readonly buffer SparseFieldChunk6 { uint field_chunk6[]; };
#endif
#if TS_FIELD_CHUNKS > 7
layout(std430, binding = TS_FIELD_CHUNK_7) readonly buffer SparseFieldChunk7 { uint field_chunk7[]; };
#endif

#define PNANOVDB_BUF_CUSTOM
struct pnanovdb_buf_t {
  uint unused;
};
uint pnanovdb_buf_read_uint32(pnanovdb_buf_t buf, uint byte_offset) {
  uint word = byte_offset >> 2u;
  uint chunk = word >> TS_FIELD_CHUNK_SHIFT;
  uint index = word & ((1u << TS_FIELD_CHUNK_SHIFT) - 1u);
  // A binary search over the chunks: three compares at most, where a chain would take seven.
  if (chunk < 4u) {
    if (chunk < 2u) return chunk == 0u ? pnanovdb_buf_data[index] : field_chunk1[index];
#if TS_FIELD_CHUNKS > 3
    return chunk == 2u ? field_chunk2[index] : field_chunk3[index];
#elif TS_FIELD_CHUNKS > 2
    return field_chunk2[index];
#endif
  }
#if TS_FIELD_CHUNKS > 4
  if (chunk < 6u) {
#if TS_FIELD_CHUNKS > 5
    return chunk == 4u ? field_chunk4[index] : field_chunk5[index];
#else
    return field_chunk4[index];
#endif
  }
#if TS_FIELD_CHUNKS > 7
  return chunk == 6u ? field_chunk6[index] : field_chunk7[index];
#elif TS_FIELD_CHUNKS > 6
  return field_chunk6[index];
#endif
#endif
  return 0u;  // past the grid: PNanoVDB never asks
}
uvec2 pnanovdb_buf_read_uint64(pnanovdb_buf_t buf, uint byte_offset) {
  return uvec2(pnanovdb_buf_read_uint32(buf, byte_offset), pnanovdb_buf_read_uint32(buf, byte_offset + 4u));
}
#define pnanovdb_grid_type_t uint
#define PNANOVDB_GRID_TYPE_GET(grid_typeIn, nameIn) pnanovdb_grid_type_constants[grid_typeIn].nameIn
#endif

#define PNANOVDB_GLSL
#include "nanovdb/PNanoVDB.h"


// One accessor per invocation: it caches the last leaf, so neighbouring reads skip the tree walk.
struct FieldReader {
  pnanovdb_readaccessor_t accessor;
};

// NanoVDB coordinates of the root tile at (0, 0, 0), where sdf::gpu_index_shift puts every band voxel
// of a grid under 3968 voxels a side.
bool field_in_first_root_tile(ivec3 ijk) {
  return all(greaterThanEqual(ijk, ivec3(0))) && all(lessThan(ijk, ivec3(4096)));
}

// Caches the upper node of the root tile at (0, 0, 0) in the accessor, so that reads in that tile
// never walk the root. Why: NVIDIA's GLSL compiler (driver 580.159.04, seen 2026-12-04 by
// tests/sdf/sparse_field_test.cpp on an H200) gives the high word of PNanoVDB's root key
// (pnanovdb_coord_to_key) as 3 where it is 0, so the root walk found no tile and every read was the
// background; llvmpipe computes it right. The accessor's own cache test (ijk ^ key above bit 12) keeps
// the node for every coordinate of the tile. Without such a tile (an empty grid) nothing is cached.
void field_prime(inout FieldReader reader) {
  pnanovdb_buf_t buf;
  pnanovdb_root_handle_t root = reader.accessor.root;
  uint tiles = pnanovdb_root_get_tile_count(buf, root);
  pnanovdb_root_tile_handle_t tile = pnanovdb_root_get_tile_zero(PNANOVDB_GRID_TYPE_FLOAT, root);
  for (uint t = 0u; t < tiles; ++t) {
    pnanovdb_uint64_t key = pnanovdb_root_tile_get_key(buf, tile);
    if (key.x == 0u && key.y == 0u && !pnanovdb_int64_is_zero(pnanovdb_root_tile_get_child(buf, tile))) {
      reader.accessor.upper = pnanovdb_root_get_child(PNANOVDB_GRID_TYPE_FLOAT, buf, root, tile);
      reader.accessor.key = ivec3(0);
      return;
    }
    tile.address = pnanovdb_address_offset(tile.address, PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_tile_size));
  }
}

// A read outside the first root tile drops the accessor's cached upper node: cache it again.
void field_keep_primed(inout FieldReader reader) {
  if (pnanovdb_address_is_null(reader.accessor.upper.address)) field_prime(reader);
}

FieldReader field_reader() {
  pnanovdb_buf_t buf;
  pnanovdb_grid_handle_t grid;
  grid.address.byte_offset = 0u;
  pnanovdb_root_handle_t root = pnanovdb_tree_get_root(buf, pnanovdb_grid_get_tree(buf, grid));
  FieldReader reader;
  pnanovdb_readaccessor_init(reader.accessor, root);
  field_prime(reader);
  return reader;
}

// The value of grid voxel `g` (grid-local integer coordinates) [world units]; off the band the
// background's +-value (tiles and inactive voxels keep the flood fill's sign). The read goes through a
// copy of the accessor, kept only for coordinates in the first root tile: a read outside it (grids of
// 3968 voxels a side or more, or probes off the grid) walks the root without dropping the primed node.
// One PNanoVDB call per read: each call is inlined, and llvmpipe's compile time follows the count.
float field_voxel(inout FieldReader reader, ivec3 g) {
  pnanovdb_buf_t buf;
  pnanovdb_coord_t ijk = g + field_params.index_offset.xyz;
  pnanovdb_readaccessor_t walker = reader.accessor;
  pnanovdb_address_t address = pnanovdb_readaccessor_get_value_address(PNANOVDB_GRID_TYPE_FLOAT, buf, walker, ijk);
  if (field_in_first_root_tile(ijk)) reader.accessor = walker;
  return pnanovdb_read_float(buf, address);
}

// Trilinear interpolation at grid-local position `x` [voxels], the same weights in the same order
// as sdf::sparse_trilinear on the host.
float field_trilinear(inout FieldReader reader, vec3 x) {
  vec3 base = floor(x);
  vec3 t = x - base;
  ivec3 g = ivec3(base);
#if defined(TS_FIELD_CHUNKS) && TS_FIELD_CHUNKS > 1
  // A chunked field reads its 8 corners in a loop whose count the compiler cannot see (a uniform, 8),
  // so the read, with its chunk branch, is inlined once instead of 8 times: llvmpipe compiled the
  // unrolled form of the gradient's 56 reads for minutes. Same reads, same order, same weights.
  float corner[8];
  for (int n = 0; n < field_params.index_offset.w; ++n) corner[n] = field_voxel(reader, g + ivec3(n & 1, (n >> 1) & 1, n >> 2));
  float c000 = corner[0], c100 = corner[1], c010 = corner[2], c110 = corner[3];
  float c001 = corner[4], c101 = corner[5], c011 = corner[6], c111 = corner[7];
#else
  float c000 = field_voxel(reader, g);
  float c100 = field_voxel(reader, g + ivec3(1, 0, 0));
  float c010 = field_voxel(reader, g + ivec3(0, 1, 0));
  float c110 = field_voxel(reader, g + ivec3(1, 1, 0));
  float c001 = field_voxel(reader, g + ivec3(0, 0, 1));
  float c101 = field_voxel(reader, g + ivec3(1, 0, 1));
  float c011 = field_voxel(reader, g + ivec3(0, 1, 1));
  float c111 = field_voxel(reader, g + ivec3(1, 1, 1));
#endif
  float c00 = mix(c000, c100, t.x), c10 = mix(c010, c110, t.x);
  float c01 = mix(c001, c101, t.x), c11 = mix(c011, c111, t.x);
  return mix(mix(c00, c10, t.y), mix(c01, c11, t.y), t.z);
}

// xyz: unit gradient of the interpolated field by central differences one voxel apart (smooth across
// voxel faces; zero off the band, where the field is constant), w: the interpolated value [world units].
vec4 field_sample(inout FieldReader reader, vec3 x) {
  float value = field_trilinear(reader, x);
  vec3 gradient = vec3(field_trilinear(reader, x + vec3(0.5, 0.0, 0.0)) - field_trilinear(reader, x - vec3(0.5, 0.0, 0.0)),
                       field_trilinear(reader, x + vec3(0.0, 0.5, 0.0)) - field_trilinear(reader, x - vec3(0.0, 0.5, 0.0)),
                       field_trilinear(reader, x + vec3(0.0, 0.0, 0.5)) - field_trilinear(reader, x - vec3(0.0, 0.0, 0.5)));
  float len = length(gradient);
  return vec4(len > 1e-6 * field_params.scale.x ? gradient / len : vec3(0.0), value);
}

#endif
