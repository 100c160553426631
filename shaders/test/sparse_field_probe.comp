#version 450
#extension GL_GOOGLE_include_directive : require
// Reads an sdf::SparseField at given grid-local positions the way the sampler and the preview do,
// so tests can compare with the host's NanoVDB/OpenVDB values. mode 0: x = the voxel value at
// round(position); mode 1: x = trilinear value; mode 2: xyz = field_sample's unit gradient, w = its value;
// modes 3 and 4 (bit patterns, for comparing the GLSL reads with the host's grid step by step): 3: the
// root's byte offset, its tile count and PNanoVDB's 64-bit root key of the voxel at round(position)
// (the key NVIDIA's driver computed wrong); 4: the byte offset of the root tile PNanoVDB's own root walk
// finds for that voxel (0: none), the value's byte offset as the reader finds it through the root table,
// the root tile's size, and the root table's entry for the voxel (-1: none); mode 5: as mode 0 with the
// accessor's root handle moved onto the grid header (whose word at the root's tile count offset is the
// grid index, 0): a read that walked PNanoVDB's root would find no tile and give the background, so
// this shows that no read depends on that walk.
#include "common/dispatch.glsl"
#include "test/bindings.h"
layout(local_size_x = 64) in;
layout(std430, binding = TS_TEST_FIELD_GRID) readonly buffer SparseField { uint pnanovdb_buf_data[]; };
// The field's parameter block at this stage's slot.
#define TS_FIELD_PARAMS TS_TEST_FIELD_PARAMS
// The field's root table (FieldRootTile[]) at this stage's slot.
#define TS_FIELD_ROOTS TS_TEST_FIELD_ROOTS
// Chunks 1-7 of a field larger than one storage block, at this stage's slots.
#define TS_FIELD_CHUNK_1 TS_TEST_FIELD_CHUNK_1
#define TS_FIELD_CHUNK_2 TS_TEST_FIELD_CHUNK_2
#define TS_FIELD_CHUNK_3 TS_TEST_FIELD_CHUNK_3
#define TS_FIELD_CHUNK_4 TS_TEST_FIELD_CHUNK_4
#define TS_FIELD_CHUNK_5 TS_TEST_FIELD_CHUNK_5
#define TS_FIELD_CHUNK_6 TS_TEST_FIELD_CHUNK_6
#define TS_FIELD_CHUNK_7 TS_TEST_FIELD_CHUNK_7
#include "common/sparse_field.glsl"
layout(std430, binding = TS_TEST_FIELD_POINTS) readonly buffer Points { vec4 points[]; };
layout(std430, binding = TS_TEST_FIELD_VALUES) writeonly buffer Values { vec4 values[]; };
#include "common/params.h"
layout(std140, binding = TS_TEST_PARAMS) uniform ProbeBlock { FieldProbeParams params; };
// TS_PROBE_MODE, when defined, fixes the mode at compile time, so a program holds one mode's reads:
// with a chunked field each PNanoVDB read inlines the chunk branch, and llvmpipe's compile time
// follows the count (all modes at once: minutes).
void main() {
#ifdef TS_PROBE_MODE
  const int mode = TS_PROBE_MODE;
#else
  int mode = params.mode.x;
#endif
  uint i = dispatch_item();
  if (i >= params.count.x) return;
  FieldReader reader = field_reader();
  vec3 x = points[i].xyz;
#if !defined(TS_FIELD_LEAVES)  // a leaf field (sdf::LeafField) has no NanoVDB root: modes 0-2 only
  if (mode == 5) reader.accessor.root.address.byte_offset = 0u;
#endif
  if (mode == 0 || mode == 5) {
    values[i] = vec4(field_voxel(reader, ivec3(round(x))), 0.0, 0.0, 0.0);
  } else if (mode == 1) {
    values[i] = vec4(field_trilinear(reader, x), 0.0, 0.0, 0.0);
  } else if (mode == 2) {
    values[i] = field_sample(reader, x);
  } else {
#if !defined(TS_FIELD_LEAVES)
    pnanovdb_buf_t buf = pnanovdb_buf_t(0u);
    pnanovdb_grid_handle_t grid;
    grid.address.byte_offset = 0u;
    pnanovdb_root_handle_t root = pnanovdb_tree_get_root(buf, pnanovdb_grid_get_tree(buf, grid));
    pnanovdb_coord_t ijk = ivec3(round(x)) + field_params.index_offset.xyz;
    // ts-audit: allow pnanovdb-root-walk (a diagnostic: the 64-bit key NVIDIA's driver computed wrong)
    pnanovdb_uint64_t key = pnanovdb_coord_to_key(ijk);
    if (mode == 3) {
      values[i] = uintBitsToFloat(uvec4(root.address.byte_offset, pnanovdb_root_get_tile_count(buf, root), key.x, key.y));
    } else {
      // ts-audit: allow pnanovdb-root-walk (a diagnostic: where PNanoVDB's own walk parts from the table)
      pnanovdb_root_tile_handle_t tile = pnanovdb_root_find_tile(PNANOVDB_GRID_TYPE_FLOAT, buf, root, ijk);
      pnanovdb_address_t address = field_value_address(reader.accessor, ijk);
      values[i] = uintBitsToFloat(uvec4(tile.address.byte_offset, address.byte_offset,
                                        PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_tile_size),
                                        uint(field_root_find(ijk))));  // int to uint keeps the bits: -1 is 0xffffffff
    }
#endif
  }
}
