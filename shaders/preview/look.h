// The preview's look, shared by the GL lighting pass (shaders/preview/shade.frag) and the CPU renderer
// (preview/cpu_renderer.cpp), so both draw the same picture from one set of figures. Plain numbers
// (float literals), valid as GLSL and as C++.
#ifndef TETRASAND_PREVIEW_LOOK_H
#define TETRASAND_PREVIEW_LOOK_H

// sRGB <-> linear light: a plain power law.
#define TS_PREVIEW_GAMMA 2.2

// Key light: Lambert diffuse weight and Blinn-Phong exponent; specular weights per layer.
#define TS_PREVIEW_DIFFUSE 0.8
#define TS_PREVIEW_SPECULAR_POWER 48.0
#define TS_PREVIEW_SPECULAR_SURFACE 0.25
#define TS_PREVIEW_SPECULAR_PARTICLE 0.35
// Hemisphere ambient: from facing down to facing up.
#define TS_PREVIEW_AMBIENT_DOWN 0.07
#define TS_PREVIEW_AMBIENT_UP 0.26
// A weak light from the camera, so shadowed sides stay readable.
#define TS_PREVIEW_CAMERA_FILL 0.10
// SDF ambient occlusion: strength of the darkening.
#define TS_PREVIEW_OCCLUSION_GAIN 1.6
// Shadow lookups push the point along its normal by this many shadow-map texels (against acne).
#define TS_PREVIEW_SHADOW_OFFSET_TEXELS 2.0

// Ground: ambient and diffuse weights, the alpha of its shadow on a transparent background, and the
// start of its fade (a fraction of the fade radius).
#define TS_PREVIEW_GROUND_AMBIENT 0.32
#define TS_PREVIEW_GROUND_DIFFUSE 0.75
#define TS_PREVIEW_GROUND_SHADOW_ALPHA 0.55
#define TS_PREVIEW_GROUND_FADE_START 0.3

#endif
