// Binding slots of the repulsion sampler's kernels, named once for GLSL and C++ (sampler/gpu_relaxer.cpp).
// tests/gpu/bindings_test.cpp checks that no kernel uses a bare number and that no two names of one
// pass share a slot. The hashed grid's slots are in shaders/common/bindings.h.
//
//   pass (kernel)               slots
//   common/grid_* (the grid)    TS_GRID_POSITIONS = TS_SAMPLER_POSITIONS_IN, TS_SORT_* (1-5)
//   sampler/relax.comp          POSITIONS_IN, POSITIONS_OUT, VELOCITIES, STEP_INFO, TS_GRID_CELL_COUNT,
//                               TS_GRID_CELL_START, TS_GRID_SORTED, SPARSE_FIELD, FIELD_ROOTS
//   sampler/reduce_steps.comp   STEP_INFO, PARTIALS
//   sampler/project.comp        POSITIONS, SPARSE_FIELD, FIELD_ROOTS
//   common/grid_* for the certificate: TS_GRID_POSITIONS = TS_CERT_CENTRES, TS_SORT_* (1-5)
//   sampler/certify_evaluate.comp  CERT_CENTRES, CERT_TRIANGLES, CERT_QUEUE, TS_GRID_CELL_COUNT,
//                               TS_GRID_CELL_START, TS_GRID_SORTED, CERT_SPLITS, CERT_UNCOVERED,
//                               CERT_BOUNDS, CERT_TOTALS
//   common/scan_* (gpu::PrefixScan) on CERT_SPLITS and CERT_UNCOVERED: TS_SCAN_* (0-1)
//   sampler/certify_scatter.comp   CERT_QUEUE, CERT_SPLITS, CERT_UNCOVERED, CERT_BOUNDS, CERT_NEXT_QUEUE,
//                               CERT_HOLES
#ifndef TETRASAND_SAMPLER_BINDINGS_H
#define TETRASAND_SAMPLER_BINDINGS_H

// Uniform-block slots (a namespace of their own in GL) of the kernels' parameter structs
// (shaders/common/params.h). A kernel's block is bound by gpu::ParamBlock::bind right before it runs,
// so kernels of different passes share a number.
#define TS_SAMPLER_PARAMS 0        // the kernel's own: RelaxParams, CertifyParams, or ItemCount
#define TS_SAMPLER_FIELD_PARAMS 1  // FieldParams of the sparse field (sampler/sdf_sample.glsl)

// TS_GRID_POSITIONS comes from shaders/common/bindings.h: a user includes both headers.

#define TS_SAMPLER_POSITIONS_IN TS_GRID_POSITIONS  // vec4: xyz position [m]; w: 1 mobile, 0 frozen
#define TS_SAMPLER_POSITIONS_OUT 1                 // vec4: the same after the step
#define TS_SAMPLER_VELOCITIES 3                    // vec4: xyz momentum step [m]
#define TS_SAMPLER_STEP_INFO 6                     // vec4 per particle: see relax.comp
#define TS_SAMPLER_PARTIALS 7                      // vec4 per 256 particles: STEP_INFO summed
#define TS_SAMPLER_POSITIONS 0                     // vec4 (project.comp): positions moved in place

// The coverage certificate (sampler/gpu_coverage_certificate.cpp); the grid's slots 2, 4 and 5 stay bound.
#define TS_CERT_CENTRES TS_GRID_POSITIONS  // vec4: xyz particle centre [m, local]
#define TS_CERT_TRIANGLES 1                // CertTriangle per mesh triangle
#define TS_CERT_QUEUE 3                    // uvec4 per sub-triangle of this level (CertLeaf.id)
#define TS_CERT_SPLITS 6                   // uint per sub-triangle + 1: 4 if split, else 0; then scanned
#define TS_CERT_UNCOVERED 7                // uint per sub-triangle + 1: 1 if left uncovered, else 0; then scanned
#define TS_CERT_BOUNDS 8                   // vec4 per sub-triangle: CertLeaf.bounds
#define TS_CERT_TOTALS 9                   // uint[4]: largest bound and largest witness (float bits), see the kernel
#define TS_CERT_NEXT_QUEUE 10              // uvec4 per sub-triangle of the next level
#define TS_CERT_HOLES 11                   // CertLeaf per sub-triangle left uncovered at this level

#define TS_SAMPLER_SPARSE_FIELD 8  // uint[]: the NanoVDB level set (sdf::SparseField), as PNanoVDB.h reads it
// Chunks 1-7 of a field larger than one storage block (sdf::SparseField, common/sparse_field.glsl).
#define TS_SAMPLER_FIELD_CHUNK_1 9
#define TS_SAMPLER_FIELD_CHUNK_2 10
#define TS_SAMPLER_FIELD_CHUNK_3 11
#define TS_SAMPLER_FIELD_CHUNK_4 12
#define TS_SAMPLER_FIELD_CHUNK_5 13
#define TS_SAMPLER_FIELD_CHUNK_6 14
#define TS_SAMPLER_FIELD_CHUNK_7 15
#define TS_SAMPLER_FIELD_ROOTS 16  // FieldRootTile[]: the field's root table (sdf::SparseField, common/sparse_field.glsl)

#endif
