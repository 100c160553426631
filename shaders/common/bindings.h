// Binding slots of the shared kernels in shaders/common, named once for GLSL and C++ (gpu/hash_grid.cpp).
// Slots are per pass: a kernel binds all it reads before it runs, so another stage may use the same
// numbers for other buffers. tests/gpu/bindings_test.cpp checks that no kernel uses a bare number
// and that no two names of one pass share a slot.
//
//   pass (kernel)               slots
//   common/scan_blocks.comp     TS_SCAN_VALUES, TS_SCAN_BLOCK_SUMS
//   common/scan_add.comp        TS_SCAN_VALUES, TS_SCAN_BLOCK_SUMS (the scanned sums, added back)
//   common/zero_uints.comp      TS_FILL_VALUES
//   common/copy_uints.comp      TS_COPY_SOURCE, TS_COPY_DESTINATION
//   common/grid_count.comp      TS_GRID_POSITIONS, TS_SORT_KEY, TS_SORT_BUCKET_COUNT, TS_SORT_SLOT
//   common/grid_scatter.comp    TS_SORT_KEY, TS_SORT_SLOT, TS_SORT_BUCKET_START, TS_SORT_SORTED
//   common/grid_sort_cells.comp TS_SORT_BUCKET_COUNT, TS_SORT_BUCKET_START, TS_SORT_SORTED
//   neighbour kernels after gpu::HashGrid::build (sampler/relax.comp, sim/contact_forces.comp):
//                               TS_GRID_CELL_COUNT, TS_GRID_CELL_START, TS_GRID_SORTED
#ifndef TETRASAND_COMMON_BINDINGS_H
#define TETRASAND_COMMON_BINDINGS_H

// Uniform-block slots (a namespace of their own in GL) of the kernels' parameter structs
// (shaders/common/params.h). A kernel's block is bound by gpu::ParamBlock::bind right before it runs,
// so kernels of different passes share a number.
#define TS_SCAN_PARAMS 0  // ItemCount: values in this level (common/scan_*.comp)
#define TS_GRID_PARAMS 0  // GridParams (common/grid_*.comp)
#define TS_FILL_PARAMS 0  // ItemCount: values cleared or copied (common/zero_uints.comp, copy_uints.comp)

// Clears and copies of uint buffers as kernels (gpu::HashGrid, gpu::BucketSort), so they can be
// GPU-decided work like the passes around them.
#define TS_FILL_VALUES 0       // uint[]: zeroed
#define TS_COPY_SOURCE 0       // uint[]
#define TS_COPY_DESTINATION 1  // uint[]

// Exclusive prefix sum (gpu::PrefixScan), one level at a time.
#define TS_SCAN_VALUES 0      // uint[]: the level scanned in place
#define TS_SCAN_BLOCK_SUMS 1  // uint[]: one sum per 512-value block (the next level)

// Counting sort of ids by key (gpu::BucketSort): the key kernel writes KEY, BUCKET_COUNT and SLOT.
#define TS_SORT_KEY 1           // uint per id: its bucket
#define TS_SORT_BUCKET_COUNT 2  // uint per bucket: ids in it (zeroed before the key kernel)
#define TS_SORT_SLOT 3          // uint per id: its place within its bucket (from an atomic counter)
#define TS_SORT_BUCKET_START 4  // uint per bucket: exclusive scan of the counts
#define TS_SORT_SORTED 5        // uint[]: ids grouped by bucket, ascending within each

// The hashed grid (gpu::HashGrid) is a bucket sort by hashed cell; neighbour kernels read its output.
#define TS_GRID_POSITIONS 0                    // vec4 per particle: xyz position [m] (grid_count's input)
#define TS_GRID_CELL_COUNT TS_SORT_BUCKET_COUNT  // particles per hashed cell
#define TS_GRID_CELL_START TS_SORT_BUCKET_START  // first index of each cell in TS_GRID_SORTED
#define TS_GRID_SORTED TS_SORT_SORTED            // particle ids by cell, ascending within a cell

#endif
