// Binding slots of the test kernels (tests/gpu/), named once for GLSL and the tests.
//   test/saxpy.comp          TS_TEST_SAXPY_X, TS_TEST_SAXPY_Y
//   test/layout_probe.comp   TS_TEST_PROBE_* (one block per shared layout; the tests read offsets back)
//   test/sparse_field_probe.comp  TS_TEST_FIELD_GRID, TS_TEST_FIELD_POINTS, TS_TEST_FIELD_VALUES, TS_TEST_FIELD_ROOTS
#ifndef TETRASAND_TEST_BINDINGS_H
#define TETRASAND_TEST_BINDINGS_H

// Uniform-block slots (a namespace of their own in GL) of the kernels' parameter structs
// (shaders/common/params.h). A kernel's block is bound by gpu::ParamBlock::bind right before it runs,
// so kernels of different passes share a number.
#define TS_TEST_PARAMS 0        // the kernel's own: SaxpyParams, SolidColorParams, FieldProbeParams
#define TS_TEST_FIELD_PARAMS 1  // FieldParams of sparse_field_probe.comp's field

#define TS_TEST_SAXPY_X 0  // float[]: x, read
#define TS_TEST_SAXPY_Y 1  // float[]: y, y <- a x + y

#define TS_TEST_PROBE_SDF_TRIANGLES 0
#define TS_TEST_PROBE_SAMPLER_GRIDS 1
#define TS_TEST_PROBE_SIM_PAIRS 2
#define TS_TEST_PROBE_SIM_PLANES 3
#define TS_TEST_PROBE_SDF_PRISMS 4
#define TS_TEST_PROBE_SIM_CYLINDERS 5
#define TS_TEST_PROBE_SIM_SPRINGS 6
#define TS_TEST_PROBE_SIM_SPRINGS64 7
#define TS_TEST_PROBE_CERT_TRIANGLES 8
#define TS_TEST_PROBE_CERT_LEAVES 9
#define TS_TEST_PROBE_FIELD_ROOTS 10

#define TS_TEST_FIELD_GRID 0    // uint[]: an sdf::SparseField's NanoVDB grid
#define TS_TEST_FIELD_POINTS 1  // vec4: xyz grid-local position [voxels]
#define TS_TEST_FIELD_VALUES 2  // vec4: what the probe read there (see the kernel)
// Chunks 1-7 of a field cut into several storage blocks (sdf::SparseField).
#define TS_TEST_FIELD_CHUNK_1 3
#define TS_TEST_FIELD_CHUNK_2 4
#define TS_TEST_FIELD_CHUNK_3 5
#define TS_TEST_FIELD_CHUNK_4 6
#define TS_TEST_FIELD_CHUNK_5 7
#define TS_TEST_FIELD_CHUNK_6 8
#define TS_TEST_FIELD_CHUNK_7 9
#define TS_TEST_FIELD_ROOTS 10  // FieldRootTile[]: the field's root table (sdf::SparseField)

#endif
