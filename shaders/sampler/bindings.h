// Binding slots of the repulsion sampler's kernels, named once for GLSL and C++ (sampler/gpu_relaxer.cpp).
// tests/gpu/bindings_test.cpp checks that no kernel uses a bare number and that no two names of one
// pass share a slot. The hashed grid's slots are in shaders/common/bindings.h.
//
//   pass (kernel)               slots
//   common/grid_* (the grid)    TS_GRID_POSITIONS = TS_SAMPLER_POSITIONS_IN, TS_SORT_* (1-5)
//   sampler/relax.comp          POSITIONS_IN, POSITIONS_OUT, VELOCITIES, STEP_INFO, TS_GRID_CELL_COUNT,
//                               TS_GRID_CELL_START, TS_GRID_SORTED, SPARSE_FIELD
//   sampler/reduce_steps.comp   STEP_INFO, PARTIALS
//   sampler/project.comp        POSITIONS, SPARSE_FIELD
#ifndef TETRASAND_SAMPLER_BINDINGS_H
#define TETRASAND_SAMPLER_BINDINGS_H

// TS_GRID_POSITIONS comes from shaders/common/bindings.h: a user includes both headers.

#define TS_SAMPLER_POSITIONS_IN TS_GRID_POSITIONS  // vec4: xyz position [m]; w: 1 mobile, 0 frozen
#define TS_SAMPLER_POSITIONS_OUT 1                 // vec4: the same after the step
#define TS_SAMPLER_VELOCITIES 3                    // vec4: xyz momentum step [m]
#define TS_SAMPLER_STEP_INFO 6                     // vec4 per particle: see relax.comp
#define TS_SAMPLER_PARTIALS 7                      // vec4 per 256 particles: STEP_INFO summed
#define TS_SAMPLER_POSITIONS 0                     // vec4 (project.comp): positions moved in place

#define TS_SAMPLER_SPARSE_FIELD 8  // uint[]: the NanoVDB level set (sdf::SparseField), as PNanoVDB.h reads it

#endif
