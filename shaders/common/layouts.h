// GPU buffer layouts: the ONE definition shared by C++ (through gpu/layouts.h) and GLSL (#include).
// Rules that keep std430 and C++ identical: every member is a 16-byte vector (vec4/uvec4/ivec4) or an
// array of them; scalars travel in the .w of a vec4. Sizes are pinned by static_assert in
// gpu/layouts.h and read back from a compiled shader in tests/gpu/layouts_test.cpp.
#ifndef TETRASAND_COMMON_LAYOUTS_H
#define TETRASAND_COMMON_LAYOUTS_H

#ifdef __cplusplus
#include <cstdint>
namespace ts::gpu::layout {
struct alignas(16) vec4 { float x, y, z, w; };
struct alignas(16) uvec4 { std::uint32_t x, y, z, w; };
struct alignas(16) ivec4 { std::int32_t x, y, z, w; };
struct alignas(32) dvec4 { double x, y, z, w; };
// A layout's alignment is its members': at least 16 (every member is a 16-byte vector), 32 with a
// dvec4. No alignas here: clang refuses one below a member's (dvec4), GCC ignored it.
#define TS_LAYOUT(name) struct name
#else
#define TS_LAYOUT(name) struct name
#endif

// ---- sdf: one triangle for scan conversion, in grid-local voxel units (voxel centres at integers).
// Pseudonormals are angle-weighted (Baerentzen & Aanaes 2005); edge e runs from vertex e to e+1.
TS_LAYOUT(SdfTriangle) {
  vec4 vertex[3];         // xyz: position [voxels]; w unused
  vec4 face_normal;       // xyz: unit face normal; w: 1 for a usable triangle, 0 if degenerate
  vec4 edge_normal[3];    // xyz: edge pseudonormal
  vec4 vertex_normal[3];  // xyz: vertex pseudonormal
};

// ---- sdf: the bounding prism of one triangle, built on the CPU in double precision. Its base is the
// triangle grown in its plane by the prism margin (3 corners), or for needle triangles, whose grown
// corners would shoot far out, the grown in-plane bounding rectangle (4 corners). The geometry shader
// extrudes the base by +-margin along the normal and slices the resulting tetrahedra.
TS_LAYOUT(SdfPrism) {
  vec4 corner[4];         // xyz: base corner [voxels]; corner[0].w: corner count (3 or 4)
  vec4 normal_margin;     // xyz: unit face normal; w: extrusion along +-normal [voxels]
};

// ---- sdf: one root tile of a sparse field's NanoVDB grid (sdf::SparseField), in the flat table the GLSL
// reader indexes instead of walking PNanoVDB's root (common/sparse_field.glsl, field_root_find): one
// entry per tile of the box of root tiles the grid spans (x slowest, z fastest), so a coordinate's
// entry is found by arithmetic on 32-bit ints, with no loop and no 64-bit root key (which NVIDIA's GLSL
// compiler computed wrong; docs/architecture.md, "The GPU field"). A box tile the grid lacks reads as
// the root's background.
TS_LAYOUT(FieldRootTile) {
  ivec4 origin;           // xyz: the tile's origin (NanoVDB index, multiples of 4096); w: 1 for an active
                          // tile value, else 0 (PNanoVDB's tile state; 0 for a tile the grid lacks)
  uvec4 address;          // x: byte offset of the tile's upper node in the grid, 0 for none;
                          // y: byte offset of the tile's value (the background's for a tile the grid lacks);
                          // z: 1 for a tile of the grid, 0 for one it lacks; w unused
};

// ---- sdf: the GPU-resident leaf field (sdf::LeafField; common/sparse_field.glsl compiled with
// TS_FIELD_LEAVES). The grid is cut into 8^3 leaf cells from grid-local voxel (0,0,0); a uint per cell
// (x fastest, then y, then z) holds the cell's slot in the values (512 floats a slot, world units,
// x fastest within the leaf) or one of these codes, which lie above any slot (sdf::kMaxLeafSlots).
#define TS_LEAF_EMPTY 0xfffffffcu    // while building: no band voxel in the cell, its sign not yet known
#define TS_LEAF_BAND 0xfffffffdu     // while building: a band leaf waiting for its slot
#define TS_LEAF_INSIDE 0xfffffffeu   // no band voxel, inside: every voxel reads -background
#define TS_LEAF_OUTSIDE 0xffffffffu  // no band voxel, outside: every voxel reads +background

// ---- sampler: shared constants of one relaxation step.
TS_LAYOUT(SamplerGrid) {
  vec4 origin_cell;       // xyz: world position of cell (0,0,0)'s corner [m]; w: cell size [m]
  uvec4 dims;             // xyz: cells along each axis of the hashed grid; w: hash table size
};

// ---- sampler: one mesh triangle of the coverage certificate (sampler/gpu_coverage_certificate.h), relative
// to the certificate's local origin: the point (a, b) of its parameter triangle (a, b >= 0, a + b <= 1)
// is corner + a edge1 + b edge2.
TS_LAYOUT(CertTriangle) {
  vec4 corner;            // xyz: vertex 0 [m, local]; w unused
  vec4 edge1;             // xyz: vertex 1 - vertex 0 [m]; w: the triangle's longest edge [m]
  vec4 edge2;             // xyz: vertex 2 - vertex 0 [m]; w unused
};

// ---- sampler: a sub-triangle of the certificate's midpoint subdivision with its bounds. Level L of
// a triangle is the regular grid of step 2^-L on its parameter triangle: the "up" sub-triangle (i, j)
// has corners (i, j), (i+1, j), (i, j+1), the "down" one (i+1, j), (i, j+1), (i+1, j+1), in steps.
// The certificate's work queue holds the ids alone (uvec4).
TS_LAYOUT(CertLeaf) {
  uvec4 id;               // x: triangle, y: level | orientation << 8 (0 up, 1 down), z: i, w: j
  vec4 bounds;            // x: upper bound U of the distance from its points to the nearest centre [m];
                          // y: distance from its centroid to the nearest centre [m] (a lower bound);
                          // z: 1 if the search was complete (U is the smallest corner bound), 0 if
                          // it stopped at its limit first; w: its longest edge [m]
};

// ---- sim: contact coefficients of one pair of materials (sim::PairCoefficients), in a table indexed
// by material_i * material_count + material_j.
TS_LAYOUT(SimPair) {
  vec4 coefficients;      // x: E* [Pa], y: friction mu, z: gamma_s [N s/m], w: dimensionless damping strength c
  vec4 extra;             // x: thesis reference speed [m/s]; y: G* [Pa] (tangential spring); zw unused
};

// ---- sim: an implicit boundary plane (smooth wall): n . x >= offset is the allowed side.
TS_LAYOUT(SimPlane) {
  vec4 normal_offset;     // xyz: unit normal into the allowed side; w: offset [m]
  // xyz: a point of the plane [m]. w > 0: the wall is only the disc of radius w about that point;
  // w < 0: the wall has a circular hole of radius -w there (a silo orifice); w == 0: infinite.
  vec4 extent;
  uvec4 material;         // x: material index
};

// ---- sim: the inside of a vertical (z) cylindrical wall (smooth), acting between two heights.
TS_LAYOUT(SimCylinder) {
  vec4 axis_radius;       // xy: the axis [m]; z unused; w: radius [m]
  vec4 range;             // x: lowest z [m], y: highest z [m]
  uvec4 material;         // x: material index
};

// ---- sim: the contact history of one particle for the tangential spring model (sim::ContactSprings):
// TS_SIM_SPRING_SLOTS slots filled from slot 0 in gather order, each a partner (particle id, -1 - wall
// index with planes first, or TS_SIM_NO_PARTNER) and the particle's elastic tangential displacement.
// SimSpringSlots64 is the same for the double-precision pipeline (TS_FP64).
#define TS_SIM_SPRING_SLOTS 12
#define TS_SIM_NO_PARTNER 0x7fffffff
TS_LAYOUT(SimSpringSlots) {
  ivec4 partner[3];       // slot s: partner[s / 4][s % 4]
  vec4 displacement[12];  // xyz: displacement [m]; w unused
};
TS_LAYOUT(SimSpringSlots64) {
  ivec4 partner[3];
  dvec4 displacement[12];
};

#ifdef __cplusplus
#undef TS_LAYOUT
}  // namespace ts::gpu::layout
#endif

// Binding slots are not layouts: each stage names its own in shaders/<stage>/bindings.h.

// Motion types (TS_SIM_BODY_VELOCITY.w)
#define TS_MOTION_DYNAMIC 0
#define TS_MOTION_KINEMATIC 1
#define TS_MOTION_STATIC 2

#endif  // TETRASAND_COMMON_LAYOUTS_H
