// Buffer bindings and texture units of the preview passes, shared by GLSL and C++ (preview/renderer.cpp).
//
// Slots per pass (program):
//   particles (particles.vert + particles.frag; shadow map and G-buffer):
//     buffers TS_PREVIEW_SPHERES, TS_PREVIEW_COLORS
//   ray cast (raycast.vert + raycast.frag; shadow map and G-buffer):
//     buffers TS_PREVIEW_SPARSE_FIELD, TS_PREVIEW_FIELD_ROOTS, unit TS_PREVIEW_UNIT_PARTICLE_DEPTH
//   shade (shade.vert + shade.frag; the lighting pass):
//     buffers TS_PREVIEW_SPARSE_FIELD, TS_PREVIEW_FIELD_ROOTS, units TS_PREVIEW_UNIT_ALBEDO, TS_PREVIEW_UNIT_NORMAL, TS_PREVIEW_UNIT_DEPTH,
//     TS_PREVIEW_UNIT_SHADOW
//   compute shadow map and G-buffer (preview/compute_passes.cpp; --gpu-path compute):
//     splat.comp: buffers TS_PREVIEW_SPHERES, TS_PREVIEW_DEPTH_BITS, TS_PREVIEW_PARTICLE_IDS
//     trace.comp: buffers TS_PREVIEW_SPHERES, TS_PREVIEW_COLORS, TS_PREVIEW_DEPTH_BITS, TS_PREVIEW_PARTICLE_IDS,
//       TS_PREVIEW_SPARSE_FIELD, TS_PREVIEW_FIELD_ROOTS, images TS_PREVIEW_IMAGE_ALBEDO, TS_PREVIEW_IMAGE_NORMAL
//
// The buffers sit at 27 and up because the simulator's kernels use bindings 0-26
// (shaders/common/layouts.h) and share the context in `tetrasand sim`, which renders its frames with
// this renderer. Every sampler has its own unit: two samplers of different types on one unit make
// draws fail (GL_INVALID_OPERATION) whether or not the shader reads them.
#ifndef TETRASAND_PREVIEW_BINDINGS_H
#define TETRASAND_PREVIEW_BINDINGS_H

// Uniform-block slots (a namespace of their own in GL) of the kernels' parameter structs
// (shaders/common/params.h). A kernel's block is bound by gpu::ParamBlock::bind right before it runs,
// so kernels of different passes share a number.
#define TS_PREVIEW_CAMERA 0        // CameraParams (preview/camera.glsl)
#define TS_PREVIEW_PARAMS 1        // the pass's own: ParticleParams, RaycastParams, ShadeParams
#define TS_PREVIEW_VOLUME 2        // VolumeParams (preview/volume.glsl)
#define TS_PREVIEW_FIELD_PARAMS 3  // FieldParams of the sparse field

#define TS_PREVIEW_SPHERES 27  // vec4[]: xyz centre relative to the scene centre [m], w radius [m]
#define TS_PREVIEW_COLORS 28   // uint[]: sRGB colour per sphere, RGBA8 with red in the low byte
#define TS_PREVIEW_SPARSE_FIELD 29  // uint[]: the NanoVDB level set (sdf::SparseField), as PNanoVDB.h reads it
// Chunks 1-7 of a field larger than one storage block (sdf::SparseField, common/sparse_field.glsl).
#define TS_PREVIEW_FIELD_CHUNK_1 30
#define TS_PREVIEW_FIELD_CHUNK_2 31
#define TS_PREVIEW_FIELD_CHUNK_3 32
#define TS_PREVIEW_FIELD_CHUNK_4 33
#define TS_PREVIEW_FIELD_CHUNK_5 34
#define TS_PREVIEW_FIELD_CHUNK_6 35
#define TS_PREVIEW_FIELD_CHUNK_7 36
#define TS_PREVIEW_FIELD_ROOTS 37  // FieldRootTile[]: the field's root table (sdf::SparseField, common/sparse_field.glsl)

// The compute passes' per-pixel buffers, zero-filled before a frame (preview/splat.glsl says why the
// complements): while splatting ~floatBitsToUint(window depth) and ~(sphere id), after trace.comp
// the plain float bits of the pixel's window depth (1.0: nothing), ready to upload into a depth texture.
#define TS_PREVIEW_DEPTH_BITS 38    // uint[]: per pixel, bottom row first
#define TS_PREVIEW_PARTICLE_IDS 39  // uint[]: per pixel, bottom row first

// Image units (a namespace of their own) the compute G-buffer writes.
#define TS_PREVIEW_IMAGE_ALBEDO 0  // rgba8: as the G-buffer's albedo target
#define TS_PREVIEW_IMAGE_NORMAL 1  // rgba16f: as the G-buffer's normal target (w: layer)

#define TS_PREVIEW_UNIT_PARTICLE_DEPTH 1  // sampler2D: window depth of the particle layer
#define TS_PREVIEW_UNIT_ALBEDO 2          // sampler2D: G-buffer albedo (sRGB)
#define TS_PREVIEW_UNIT_NORMAL 3          // sampler2D: G-buffer unit normal (xyz) and layer (w)
#define TS_PREVIEW_UNIT_DEPTH 4           // sampler2D: G-buffer window depth
#define TS_PREVIEW_UNIT_SHADOW 5          // sampler2DShadow: the key light's depth map

// G-buffer layers (normal.w).
#define TS_PREVIEW_LAYER_BACKGROUND 0
#define TS_PREVIEW_LAYER_SURFACE 1
#define TS_PREVIEW_LAYER_PARTICLE 2

#endif
