// Buffer bindings and texture units of the sdf passes, shared by GLSL and C++ (sdf/scan_convert.cpp,
// sdf/compute_scan.cpp).
//
// Slots per pass (program):
//   scan conversion (scan_convert.vert + scan_convert.geom + scan_convert.frag):
//     buffers TS_SDF_PRISMS (geometry stage), TS_SDF_TRIANGLES (fragment stage)
//   compute scan conversion, triangle/brick pairs (brick_pairs.comp: ROW_SPANS, COUNT and SCATTER
//     variants): buffers TS_SDF_TRIANGLES, TS_SDF_PAIR_SPANS, TS_SDF_PAIR_TRIANGLE_ROWS,
//     TS_SDF_PAIR_ROW_COUNTS, TS_SDF_PAIRS_OUT; between ROW_SPANS and COUNT the spans are scanned
//     (common/scan_*.comp), and between COUNT and SCATTER the host turns the row counts into row starts
//   compute scan conversion of a slab, per-brick lists (scan_bricks.comp, BRICK_COUNT and BRICK_SCATTER
//     variants): buffers TS_SDF_PAIRS, TS_SDF_PAIR_ROWS, TS_SDF_PAIR_SLOTS, TS_SDF_BRICK_STARTS,
//     TS_SDF_BRICK_TRIANGLES; between them TS_SCAN_VALUES = the brick counts, scanned in place
//   compute scan conversion of a slab, the brick pass (scan_bricks.comp): buffers TS_SDF_TRIANGLES,
//     TS_SDF_BRICK_STARTS, TS_SDF_BRICK_TRIANGLES, image unit TS_SDF_IMAGE_SLAB
//   band flags (band_flags.comp): texture unit TS_SDF_UNIT_SLAB, buffer TS_SDF_BAND_FLAGS
//   exclusive scan of the flags (common/scan_*.comp): TS_SCAN_VALUES = the flags, scanned in place
//   band scatter (band_scatter.comp): texture unit TS_SDF_UNIT_SLAB, buffers TS_SDF_BAND_OFFSETS,
//     TS_SDF_BAND_INDICES, TS_SDF_BAND_VALUES
//   leaf field, per slab (sdf/leaf_field.h): leaf_flags.comp: unit TS_SDF_UNIT_SLAB, buffers
//     TS_SDF_LEAF_INDEX, TS_SDF_LEAF_FLAGS, TS_SDF_LEAF_COUNTS; the exclusive scan of the flags;
//     leaf_assign.comp: TS_SDF_LEAF_INDEX, TS_SDF_LEAF_FLAGS, TS_SDF_LEAF_COUNTS; leaf_fill.comp: unit
//     TS_SDF_UNIT_SLAB, buffers TS_SDF_LEAF_INDEX, TS_SDF_LEAF_VALUES; after the last slab
//     leaf_signs.comp: TS_SDF_LEAF_INDEX, TS_SDF_LEAF_VALUES
//
// Each pass binds its slots before it runs, so the passes may share slot numbers.
#ifndef TETRASAND_SDF_BINDINGS_H
#define TETRASAND_SDF_BINDINGS_H

// Uniform-block slots (a namespace of their own in GL) of the kernels' parameter structs
// (shaders/common/params.h). A kernel's block is bound by gpu::ParamBlock::bind right before it runs,
// so kernels of different passes share a number.
#define TS_SDF_SCAN_PARAMS 0     // ScanConvertParams: one entry per draw (gpu::ParamArray)
#define TS_SDF_BAND_PARAMS 0     // BandParams (band_flags.comp, band_scatter.comp)
#define TS_SDF_COMPUTE_PARAMS 0  // ComputeScanParams (scan_bricks.comp)
#define TS_SDF_PAIR_PARAMS 0     // BrickPairParams (brick_pairs.comp)
#define TS_SDF_LEAF_PARAMS 0     // LeafBuildParams (leaf_*.comp)

#define TS_SDF_TRIANGLES 0     // SdfTriangle[]: the triangles in grid-local voxel units
#define TS_SDF_PRISMS 1        // SdfPrism[]: each triangle's bounding prism

// The compute path: a voxel brick is BRICK^3 voxels, one work group of scan_bricks.comp; the host
// compiles it with BRICK 2 or 4 (sdf::compute_brick_side) and pairs the triangles with the same bricks.
#define TS_SDF_PAIRS 1             // uvec2 per triangle/brick pair: triangle, brick x | brick y << 16
#define TS_SDF_PAIR_ROWS 2         // uint per brick row (brick z) + 1: its first pair (pairs sorted by row)
#define TS_SDF_PAIR_SLOTS 3        // uint per pair of the slab: its place among its brick's pairs
#define TS_SDF_BRICK_STARTS 4      // uint per brick of the slab + 1: its pairs, scanned: its first triangle
#define TS_SDF_BRICK_TRIANGLES 5   // uint per pair of the slab: the triangles, listed brick by brick
// Making the pairs (brick_pairs.comp): a "triangle row" is one brick row a triangle's grown box spans.
#define TS_SDF_PAIR_SPANS 1          // uint per triangle: its triangle rows; scanned in place: its first one
#define TS_SDF_PAIR_TRIANGLE_ROWS 2  // uint per triangle row: the triangle's first place within the row
#define TS_SDF_PAIR_ROW_COUNTS 3     // uint per brick row: COUNT adds its pairs; SCATTER reads its first pair
#define TS_SDF_PAIRS_OUT 4           // uvec2 per pair, as TS_SDF_PAIRS: written by SCATTER
#define TS_SDF_IMAGE_SLAB 0        // image2DArray rgba32f: the slab target, written by scan_bricks.comp

#define TS_SDF_UNIT_SLAB 0     // sampler2DArray rgba32f: the finished slab (unit gradient, distance [voxels])
#define TS_SDF_BAND_FLAGS 0    // uint per slab voxel: 1 in the band
#define TS_SDF_BAND_OFFSETS 0  // uint per slab voxel: exclusive scan of the flags (the same buffer)
#define TS_SDF_BAND_INDICES 1  // uint per band voxel: its slab index, ascending
#define TS_SDF_BAND_VALUES 2   // vec4 per band voxel: its value as the slab holds it

// The leaf field (sdf::LeafField; the codes and the leaf layout in common/layouts.h).
#define TS_SDF_LEAF_INDEX 0    // uint per leaf cell of the grid: slot or TS_LEAF_* code
#define TS_SDF_LEAF_FLAGS 1    // uint per leaf cell of the slab: 1 for a band leaf, then scanned in place
#define TS_SDF_LEAF_VALUES 2   // float[512] per slot: the leaf's values [world units]
#define TS_SDF_LEAF_COUNTS 3   // uvec4: xy slots used before this slab (alternating, LeafBuildParams.cells.w),
                               // z band voxels, w 1 once a band leaf found no slot (the bound was wrong)

#endif
