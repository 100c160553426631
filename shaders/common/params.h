// Kernel parameters: the ONE definition shared by C++ (through gpu/params.h) and GLSL (#include). Each
// kernel, or each pass whose kernels share parameters, reads one of these structs from a std140
// uniform block whose one member is the struct (sim/contact_forces.comp: ContactBlock holding
// SimContactParams params), at a slot its stage's bindings.h names, and the host uploads the same
// struct through gpu::ParamBlock. A misspelt member is then a compile error on both sides instead of
// a by-name uniform that GL silently ignores.
// Rules that keep std140 and C++ identical (as in layouts.h): every member is a 16-byte vector
// (vec4/uvec4/ivec4), a mat4 (four vec4 columns) or a 32-byte dvec4 at a 32-byte offset; scalars
// travel in components. Sizes and offsets are pinned by static_assert in gpu/params.h and read back
// from the compiled programs in tests/gpu/params_test.cpp.
#ifndef TETRASAND_COMMON_PARAMS_H
#define TETRASAND_COMMON_PARAMS_H

#include "layouts.h"  // the vector types; a path both compilers find beside this file

#ifdef __cplusplus
namespace ts::gpu::params {
using layout::dvec4;
using layout::ivec4;
using layout::uvec4;
using layout::vec4;
struct alignas(16) mat4 { vec4 column[4]; };  // column-major, as GLSL's mat4 in std140
#define TS_PARAMS(name) struct name
#else
#define TS_PARAMS(name) struct name
#endif

// ---- Kernels whose one parameter is how many items they cover (common/scan_*.comp,
// common/zero_uints.comp, common/copy_uints.comp, sampler/project.comp,
// sampler/reduce_steps.comp, sampler/certify_scatter.comp, sim/update_particles.comp,
// sim/reduce_particle_stats.comp, sim/resort_ranges.comp, sim/resort_particles.comp).
TS_PARAMS(ItemCount) {
  uvec4 count;            // x: items (values, particles, bodies, sub-triangles); yzw unused
};

// ---- common: the hashed grid's counting sort (common/grid_*.comp) and the simulator's re-sort key
// kernel (sim/resort_keys.comp), which feeds the same sort.
TS_PARAMS(GridParams) {
  uvec4 sizes;            // x: ids (particles or bodies), y: hash table size (buckets); zw unused
  vec4 cell;              // x: cell size [m]; yzw unused
};

// ---- common: where a sparse NanoVDB field sits (common/sparse_field.glsl, sdf::SparseField::bind).
TS_PARAMS(FieldParams) {
  ivec4 index_offset;     // xyz: NanoVDB index of the grid spec's voxel (0,0,0); w: 8, the corners
                          // a chunked field's trilinear read loops over (a count the compiler cannot see)
  vec4 scale;             // x: voxel size [world units]; y: |value| off the band [world units]; zw unused
  ivec4 root_first;       // xyz: tile index (origin / 4096) of the root table's first entry; w unused.
                          // A leaf field (TS_FIELD_LEAVES): xyz: its leaf cells along x, y, z
  uvec4 roots;            // xyz: extent of the root table's box [root tiles]; w: byte offset of the
                          // root's background value in the grid (what a coordinate off the box reads).
                          // A leaf field: unused
};

// ---- sampler/relax.comp: one relaxation step.
TS_PARAMS(RelaxParams) {
  uvec4 sizes;            // x: particles, y: hash table size; zw unused
  vec4 kernel;            // x: cell size = repulsion cutoff [m], y: 1 / (2 sigma^2) [1/m^2],
                          // z: repulsion gain (dimensionless step on the kernel sum), w: momentum beta in [0, 1)
  vec4 limits;            // x: max move per step (CFL guard) [m], y: |phi| beyond which a particle has
                          // left the band [m]; zw unused
};

// ---- sampler/certify_evaluate.comp: one level of the coverage certificate.
TS_PARAMS(CertifyParams) {
  uvec4 sizes;            // x: sub-triangles in the queue, y: hash table size, z: 1 when every
                          // sub-triangle is final (the queue budget was reached); w unused
  ivec4 search;           // x: the search stops after this many shells around the centroid's cell; yzw unused
  vec4 lengths;           // x: cell size of the hashed grid [m], y: search slack (float error of cell
                          // indices; shell R is complete to R cell - slack) [m], z: test radius (the
                          // ball radius less the float margin) [m], w: floor length (a sub-triangle
                          // whose longest edge is at most this is not split) [m]
  vec4 refine;            // x: hole resolution (the floor for partly uncovered ones once a hole is
                          // proven) [m], y: refine tolerance (sub-triangles with U > witness + this are
                          // split) [m], z: largest witness of the earlier levels [m]; w unused
};

// ---- sdf/scan_convert.{vert,geom,frag}: one draw of the scan conversion.
TS_PARAMS(ScanConvertParams) {
  ivec4 layers;           // x: grid z of render-target layer 0 (the slab's first), y: layers of this
                          // slab inside the grid (the last slab's render target has more; slicing
                          // them would be wasted work), z: first render-target layer this draw covers, w: layers
                          // this draw covers (at most INVOCATIONS * LAYERS_PER_INVOCATION)
  vec4 grid;              // xy: grid dims along x and y = viewport size, z: |d| [voxels] that maps to
                          // depth 1 (beyond it the fragment is dropped); w unused
};

// ---- sdf/band_flags.comp and sdf/band_scatter.comp: the band compaction of one slab.
TS_PARAMS(BandParams) {
  ivec4 layer_size;       // xy: voxels along x, y; zw unused
  uvec4 voxels;           // x: layer_size.x * layer_size.y * layers; yzw unused
  vec4 band;              // x: half-width [voxels]; yzw unused
};

// ---- sdf/leaf_flags.comp, sdf/leaf_assign.comp, sdf/leaf_fill.comp, sdf/leaf_signs.comp: the GPU-resident
// leaf field built from each finished slab (sdf/leaf_field.h).
TS_PARAMS(LeafBuildParams) {
  ivec4 grid;             // xyz: grid dims [voxels]; w: grid z of the slab's layer 0 (a multiple of 8)
  ivec4 leaves;           // xyz: leaf cells of the grid along x, y, z; w: leaf rows (cells along z) of the slab
  uvec4 cells;            // x: leaf cells of the slab; y: index of its first cell in the grid's;
                          // z: leaf slots the values hold; w: which counter holds the slots used so far (0, 1)
  vec4 band;              // x: half-width [voxels]; y: voxel size [world units]; z: |value| off the band
                          // [world units]; w unused
};

// ---- sdf/brick_pairs.comp: the compute scan conversion's triangle/brick pairs, made on the GPU
// (sdf/compute_scan.h, BrickPairGenerator).
TS_PARAMS(BrickPairParams) {
  ivec4 grid;    // xyz: grid dims [voxels]; w: brick side [voxels]
  ivec4 bricks;  // xyz: bricks along each axis; w unused
  uvec4 counts;  // x: triangles; yzw unused
  vec4 reach;    // x: margin [voxels]; y: half the span of a brick's voxel centres, (brick - 1) / 2;
                 // z: the squared radius a brick centre may lie from the triangle, (margin + y * sqrt 3)^2
};

// ---- sdf/scan_bricks.comp: the compute scan conversion of one slab (sdf/compute_scan.h).
TS_PARAMS(ComputeScanParams) {
  ivec4 grid;   // xyz: grid dims [voxels]; w: brick rows (bricks along z) of the whole grid
  ivec4 slab;   // x: grid z of slab layer 0; y: layers of this slab; z: its first brick row; w unused
  uvec4 pairs;  // x: first triangle/brick pair of this slab; y: its pairs; z: bricks of its brick rows;
                // w unused
  vec4 band;    // x: half-width [voxels]; yzw unused
};

// ---- sim/contact_forces.comp. SimContactParams64 is the same for the double-precision pipelines
// (TS_FP64), whose step length is a double. The contact law, springs, walls present and the
// penetration check are compile-time switches of the kernel (TS_CONTACT_*), not parameters.
TS_PARAMS(SimContactParams) {
  uvec4 sizes;            // x: particles, y: hash table size, z: planes (walls), w: cylinders
  uvec4 materials;        // x: material count; yzw unused
  vec4 limits;            // x: cell size of the hashed grid [m] (largest diameter + skin), y: overlap
                          // clamp ratio (thesis 3.3.1): delta <= ratio * min radius
  vec4 step;              // x: dt [s], advances the springs; yzw unused
  uvec4 lists;            // x: candidate list capacity K per particle (TS_SIM_LIST); yzw unused
};
TS_PARAMS(SimContactParams64) {
  uvec4 sizes;
  uvec4 materials;
  vec4 limits;
  uvec4 lists;            // before step, which std140 puts at the next 32-byte offset (64) either way
  dvec4 step;
};

// ---- sim/bond_forces.comp and sim/bond_sums.comp: the bonds of breakable props. SimBondParams64 is
// the same for the double-precision pipelines (TS_FP64), whose step length is a double.
TS_PARAMS(SimBondParams) {
  uvec4 sizes;            // x: bonds, y: particles; zw unused
  vec4 step;              // x: dt [s]; yzw unused
};
TS_PARAMS(SimBondParams64) {
  uvec4 sizes;
  dvec4 step;             // at 32 (std140 aligns a dvec4 to 32 bytes)
};

// ---- sim/list_decide.comp and sim/list_build.comp: the contact candidate lists (sim/contact_lists.h).
TS_PARAMS(SimListParams) {
  uvec4 sizes;            // x: particles, y: hash table size, z: list capacity K per particle, w: rows of
                          // the rebuild's indirect dispatch plan (TS_SIM_LIST_PLAN)
  vec4 lengths;           // x: cell size of the hashed grid [m] (largest diameter + skin), y: skin [m],
                          // z: the list's cut-off beyond ri + rj [m] (the skin and a rounding margin); w unused
};

// ---- sim/integrate_bodies.comp (SimIntegrateParams64 with TS_FP64).
TS_PARAMS(SimIntegrateParams) {
  uvec4 sizes;            // x: bodies; yzw unused
  ivec4 models;           // x: 0 forward Euler (thesis), 1 semi-implicit Euler; yzw unused
  vec4 limits;            // x: CFL speed clamp cfl * cell / dt [m/s], y: angular damping rate [1/s]
                          // (0 = off, thesis pseudocode 4.4), z: damp when |v| + |w| reach is below
                          // this [m/s]; w unused
  vec4 gravity_dt;        // xyz: gravity [m/s^2], w: dt [s]
  vec4 time;              // x: the time this step ends at [s] (keyframed bodies); yzw unused
};
TS_PARAMS(SimIntegrateParams64) {
  uvec4 sizes;
  ivec4 models;
  vec4 limits;
  dvec4 gravity_dt;
  dvec4 time;
};

// ---- sim/reduce_metrics.comp.
TS_PARAMS(SimMetricsParams) {
  uvec4 sizes;            // x: bodies; yzw unused
  vec4 gravity;           // xyz: gravity [m/s^2]; w unused
};

// ---- sim/resort_fixup.comp.
TS_PARAMS(SimFixupParams) {
  uvec4 sizes;            // x: particles; yzw unused
  ivec4 models;           // x: 1 when the particles carry tangential springs; yzw unused
};

// ---- sim/gather_rows.comp.
TS_PARAMS(SimGatherParams) {
  uvec4 shape;            // x: rows, y: uvec4 per row; zw unused
};

// ---- preview/camera.glsl: the camera every preview pass shares. Positions relative to the scene centre.
TS_PARAMS(CameraParams) {
  mat4 view_projection;          // world -> clip (depth -1..1)
  mat4 inverse_view_projection;  // clip -> world
  vec4 eye;                      // xyz: pinhole position (perspective lens) [m]
  vec4 forward;                  // xyz: unit, the camera's forward axis
  vec4 right;                    // xyz: unit
  vec4 up;                       // xyz: unit, the image's up axis
  ivec4 lens;                    // x: 1 parallel rays along forward (orthographic); yzw unused
  vec4 viewport;                 // xy: [pixels]; zw unused
};

// ---- preview/volume.glsl: the SDF box the ray cast and the lighting read.
TS_PARAMS(VolumeParams) {
  vec4 origin_voxel;      // xyz: voxel (0,0,0)'s centre, relative to the scene centre [m]; w: voxel size [m]
  vec4 dims_band;         // xyz: voxels along x, y, z; w: |distance| saturates here [voxels]
};

// ---- preview/particles.vert.
TS_PARAMS(ParticleParams) {
  ivec4 flags;            // x: 1 colours from the per-particle buffer, else color; yzw unused
  vec4 color;             // xyz: sRGB; w unused
};

// ---- preview/raycast.frag.
TS_PARAMS(RaycastParams) {
  ivec4 flags;            // x: 1 stops at the particle depth, y: 1 depth only (shadow pass, no
                          // normal), z: most refinement steps per crossing; w unused
  vec4 steps;             // x: shortest step [voxels] (grazing rays still advance); yzw unused
  vec4 surface_color;     // xyz: sRGB; w unused
};

// ---- preview/splat.comp, trace.comp: the compute shadow map and G-buffer.
// flags.z and steps.x mean what RaycastParams' do: preview/march.glsl reads them from either.
TS_PARAMS(PreviewComputeParams) {
  ivec4 flags;            // x: 1 colours from the per-particle buffer, else particle_color; y: 1 depth
                          // only (shadow map); z: most refinement steps per crossing; w: 1 has a volume
  uvec4 sizes;            // x: spheres, y: 8 x 8 tiles along x, z: image width, w: image height [pixels]
  vec4 steps;             // x: shortest step [voxels] (grazing rays still advance); yzw unused
  vec4 surface_color;     // xyz: sRGB; w unused
  vec4 particle_color;    // xyz: sRGB; w unused
  ivec4 mode;             // x: splat.comp's pass, 0 depths, 1 ids (one program, so both passes
                          // compute bit-identical depths); yzw unused
};

// ---- preview/shade.frag: the lighting pass.
TS_PARAMS(ShadeParams) {
  mat4 light_view_projection;  // relative world -> the light's clip space
  ivec4 flags;            // x: shadows, y: has a volume, z: draws the ground plane, w: transparent
                          // (alpha 0 background, the ground only as its shadow); each 1 or 0
  vec4 shadow;            // x: [m] per shadow-map texel, y: bias (window-depth units), zw: 1 / shadow-map size
  vec4 light_dir;         // xyz: unit, towards the key light
  vec4 world_up;          // xyz: unit
  vec4 ground;            // xyz: the ground's centre (relative world) [m], w: the plane
                          // dot(world_up, p) = w [m, relative]
  vec4 ground_color;      // xyz: sRGB, w: the ground fades out towards this distance [m]
  vec4 background_top;    // xyz: sRGB
  vec4 background_bottom; // xyz: sRGB
};

// ---- test/saxpy.comp.
TS_PARAMS(SaxpyParams) {
  uvec4 count;            // x: items
  vec4 scale;             // x: a
};

// ---- test/solid_color.frag.
TS_PARAMS(SolidColorParams) {
  vec4 color;             // rgba
};

// ---- test/sparse_field_probe.comp.
TS_PARAMS(FieldProbeParams) {
  uvec4 count;            // x: points
  ivec4 mode;             // x: what the probe reads (see the kernel)
};

#ifdef __cplusplus
#undef TS_PARAMS
}  // namespace ts::gpu::params
#endif

#endif  // TETRASAND_COMMON_PARAMS_H
