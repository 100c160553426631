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

#if defined(TS_FIELD_LEAVES)
// The GPU-resident leaf field (sdf::LeafField, built by the scan conversion on the GPU; compiled with
// TS_FIELD_LEAVES, sdf::LeafField::shader_defines): 8^3 leaves from grid-local voxel (0,0,0). The
// kernel's SparseField block holds the leaves' values (512 floats a slot as uint bits, x fastest), the
// root table's slot holds the leaf index (a uint per leaf cell, x fastest: slot or TS_LEAF_* code;
// common/layouts.h), and field_params.root_first.xyz the leaf cells along x, y, z. The same
// field_voxel/field_trilinear/field_sample as the NanoVDB reader, the same values voxel for voxel.
#include "common/layouts.h"
// One block name, FieldIndex, in both variants (the leaf index here, the root table below): the slot holds
// one or the other, as tests/gpu/bindings_test.cpp checks a slot of a pass holds one block.
layout(std430, binding = TS_FIELD_ROOTS) readonly buffer FieldIndex { uint field_leaf_index[]; };

struct FieldReader {
  uint unused;  // no cache: a read is one index load and one value load
};

FieldReader field_reader() { return FieldReader(0u); }

// The value of grid voxel `g` (grid-local integer coordinates) [world units]; off the band +-background,
// and +background off the grid (which holds the mesh with a margin: outside).
float field_voxel(inout FieldReader reader, ivec3 g) {
  ivec3 cells = field_params.root_first.xyz;
  ivec3 cell = g >> 3;  // >> of a signed int extends the sign: negative coordinates round down
  float background = field_params.scale.y;
  if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, cells))) return background;
  uint entry = field_leaf_index[(cell.z * cells.y + cell.y) * cells.x + cell.x];
  if (entry >= TS_LEAF_EMPTY) return entry == TS_LEAF_INSIDE ? -background : background;
  ivec3 local = g & 7;
  return uintBitsToFloat(pnanovdb_buf_data[entry * 512u + uint((local.z << 6) | (local.y << 3) | local.x)]);
}

#else  // the NanoVDB field

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
#if TS_FIELD_CHUNK_SHIFT < 1 || TS_FIELD_CHUNK_SHIFT > 30
#error "a chunk holds 2^TS_FIELD_CHUNK_SHIFT words: a shift of 32 or more is undefined, and 32-bit addresses need at most 30"
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


// The root as a flat table (FieldRootTile, sdf::gpu_root_table), bound at the slot the kernel's stage
// names TS_FIELD_ROOTS: one entry per tile of the box of root tiles the grid spans, so every read finds
// its root tile by arithmetic on 32-bit ints, and PNanoVDB's 32-bit-safe upper, lower and leaf reads go
// on from the tile's upper node. PNanoVDB's own root walk (pnanovdb_root_find_tile) compares 64-bit
// keys made of two 32-bit words, and NVIDIA's GLSL compiler (driver 580.159.04, H200, seen 2026-12-04)
// computed the key's high word as 3 where it is 0, so the walk found no tile and every read was the
// background; llvmpipe computed it right. No read here goes through that walk
// (tests/sdf/sparse_field_test.cpp, tests/gpu/shader_audit.py). No search loop either: each read is
// inlined, and llvmpipe's compile time follows what the reads inline.
layout(std430, binding = TS_FIELD_ROOTS) readonly buffer FieldIndex { FieldRootTile field_roots[]; };

// One accessor per invocation: it caches the last leaf, lower and upper node, so neighbouring reads
// skip the tree walk, and a read in the cached upper node skips the root table too.
struct FieldReader {
  pnanovdb_readaccessor_t accessor;
};

// The entry of the root tile holding NanoVDB coordinate `ijk`, or -1 off the table's box.
int field_root_find(ivec3 ijk) {
  // >> of a signed int extends the sign (GLSL 4.50, 5.9): the tile index rounds negative coordinates down.
  ivec3 rel = (ijk >> 12) - field_params.root_first.xyz;
  ivec3 extent = ivec3(field_params.roots.xyz);
  if (any(lessThan(rel, ivec3(0))) || any(greaterThanEqual(rel, extent))) return -1;
  return (rel.x * extent.y + rel.y) * extent.z + rel.z;  // no overflow: the host caps the box's size
}

// The root step of a read at `ijk` that missed the accessor's cached nodes: finds the root tile in the
// table and, where it has an upper node, caches that in the accessor (as PNanoVDB's root step does) and
// returns true; else returns false with `address` at the tile's value or the root's background.
bool field_root_step(inout pnanovdb_readaccessor_t acc, ivec3 ijk, out pnanovdb_address_t address) {
  int t = field_root_find(ijk);
  address.byte_offset = t < 0 ? field_params.roots.w : field_roots[t].address.y;
  if (t < 0 || field_roots[t].address.x == 0u) return false;
  acc.upper.address.byte_offset = field_roots[t].address.x;
  acc.key = ijk;
  return true;
}

// The byte address of the value at `ijk`: PNanoVDB's accessor read (pnanovdb_readaccessor_get_value_address)
// with its root step replaced by the root table. One exit and one inlined upper-node read: llvmpipe's
// compile time follows the inlined code, and a kernel inlines this once per voxel read.
pnanovdb_address_t field_value_address(inout pnanovdb_readaccessor_t acc, ivec3 ijk) {
  pnanovdb_buf_t buf = pnanovdb_buf_t(0u);  // unused by the reads (they read the bound blocks): set, so nothing reads an undefined value
  int dirty = pnanovdb_readaccessor_computedirty(acc, ijk);
  pnanovdb_address_t address;
  if (pnanovdb_readaccessor_iscached0(acc, dirty)) {
    address = pnanovdb_leaf_get_value_address_and_cache(PNANOVDB_GRID_TYPE_FLOAT, buf, acc.leaf, ijk, acc);
  } else if (pnanovdb_readaccessor_iscached1(acc, dirty)) {
    address = pnanovdb_lower_get_value_address_and_cache(PNANOVDB_GRID_TYPE_FLOAT, buf, acc.lower, ijk, acc);
  } else if (pnanovdb_readaccessor_iscached2(acc, dirty) || field_root_step(acc, ijk, address)) {
    address = pnanovdb_upper_get_value_address_and_cache(PNANOVDB_GRID_TYPE_FLOAT, buf, acc.upper, ijk, acc);
  }
  return address;
}

// The edge of the node or tile holding `ijk` [voxels] (1 in a leaf): pnanovdb_readaccessor_get_dim
// with the root table, for NanoVDB's hierarchical DDA (preview/raycast.frag).
uint field_dim(inout pnanovdb_readaccessor_t acc, ivec3 ijk) {
  pnanovdb_buf_t buf = pnanovdb_buf_t(0u);  // unused by the reads (they read the bound blocks): set, so nothing reads an undefined value
  int dirty = pnanovdb_readaccessor_computedirty(acc, ijk);
  pnanovdb_address_t unused;
  uint dim = 4096u;  // the root's background or a tile value: a root tile's edge
  if (pnanovdb_readaccessor_iscached0(acc, dirty)) {
    dim = 1u;
  } else if (pnanovdb_readaccessor_iscached1(acc, dirty)) {
    dim = pnanovdb_lower_get_dim_and_cache(PNANOVDB_GRID_TYPE_FLOAT, buf, acc.lower, ijk, acc);
  } else if (pnanovdb_readaccessor_iscached2(acc, dirty) || field_root_step(acc, ijk, unused)) {
    dim = pnanovdb_upper_get_dim_and_cache(PNANOVDB_GRID_TYPE_FLOAT, buf, acc.upper, ijk, acc);
  }
  return dim;
}

// Whether the value at `ijk` is active (a band voxel): pnanovdb_readaccessor_is_active with the root table.
bool field_is_active(inout pnanovdb_readaccessor_t acc, ivec3 ijk) {
  pnanovdb_buf_t buf = pnanovdb_buf_t(0u);  // unused by the reads (they read the bound blocks): set, so nothing reads an undefined value
  int dirty = pnanovdb_readaccessor_computedirty(acc, ijk);
  pnanovdb_address_t unused;
  bool is_active;
  if (pnanovdb_readaccessor_iscached0(acc, dirty)) {
    is_active = pnanovdb_leaf_is_active_and_cache(PNANOVDB_GRID_TYPE_FLOAT, buf, acc.leaf, ijk, acc);
  } else if (pnanovdb_readaccessor_iscached1(acc, dirty)) {
    is_active = pnanovdb_lower_is_active_and_cache(PNANOVDB_GRID_TYPE_FLOAT, buf, acc.lower, ijk, acc);
  } else if (pnanovdb_readaccessor_iscached2(acc, dirty) || field_root_step(acc, ijk, unused)) {
    is_active = pnanovdb_upper_is_active_and_cache(PNANOVDB_GRID_TYPE_FLOAT, buf, acc.upper, ijk, acc);
  } else {
    int t = field_root_find(ijk);  // a root tile's state; off the box: the background, inactive
    is_active = t >= 0 && field_roots[t].origin.w != 0;
  }
  return is_active;
}

FieldReader field_reader() {
  pnanovdb_buf_t buf = pnanovdb_buf_t(0u);  // unused by the reads (they read the bound blocks): set, so nothing reads an undefined value
  pnanovdb_grid_handle_t grid;
  grid.address.byte_offset = 0u;
  pnanovdb_root_handle_t root = pnanovdb_tree_get_root(buf, pnanovdb_grid_get_tree(buf, grid));
  FieldReader reader;
  pnanovdb_readaccessor_init(reader.accessor, root);  // the root handle: for its bounding box only
  return reader;
}

// The value of grid voxel `g` (grid-local integer coordinates) [world units]; off the band the
// background's +-value (tiles and inactive voxels keep the flood fill's sign).
// One read per call: each call is inlined, and llvmpipe's compile time follows the count.
float field_voxel(inout FieldReader reader, ivec3 g) {
  pnanovdb_buf_t buf = pnanovdb_buf_t(0u);  // unused by the reads (they read the bound blocks): set, so nothing reads an undefined value
  return pnanovdb_read_float(buf, field_value_address(reader.accessor, g + field_params.index_offset.xyz));
}

#endif  // TS_FIELD_LEAVES

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
  // `n & 7`: the array's range whatever the uniform holds (an index past it is undefined in GLSL).
  for (int n = 0; n < field_params.index_offset.w; ++n) corner[n & 7] = field_voxel(reader, g + ivec3(n & 1, (n >> 1) & 1, (n >> 2) & 1));
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
