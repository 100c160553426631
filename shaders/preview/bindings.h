// Buffer bindings and texture units of the preview passes, shared by GLSL and C++ (preview/renderer.cpp).
// Bindings 26 and up stay clear of the simulator's (0-25), which shares the context in `tetrasand sim`.
#ifndef TETRASAND_PREVIEW_BINDINGS_H
#define TETRASAND_PREVIEW_BINDINGS_H

#define TS_PREVIEW_SPHERES 26  // vec4[]: xyz centre relative to the scene centre [m], w radius [m]
#define TS_PREVIEW_COLORS 27   // uint[]: sRGB colour per sphere, RGBA8 with red in the low byte

#define TS_PREVIEW_UNIT_VOLUME 0          // sampler3D: signed distance [voxels]
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
