#pragma once
// Colours of the preview: the scalar colour map (viridis, sampled at nine stops and interpolated
// linearly, dark blue 0 -> yellow 1), a categorical map (distinct colours per key), sRGB packing,
// and the palette of simulation frames.
#include <Eigen/Core>
#include <cstdint>

namespace ts::preview {

// sRGB colour of the viridis map at t (clamped to [0, 1]).
Eigen::Vector3f viridis(double t);

// RGBA8 with red in the low byte (GLSL unpackUnorm4x8), alpha 255.
std::uint32_t pack_rgba8(const Eigen::Vector3f& srgb);

// One of many distinct colours for `key` (bodies in frames coloured by body): hues a golden angle
// apart, saturation and value alternating, so neighbouring keys differ.
Eigen::Vector3f categorical(std::uint32_t key);

// A colour varied in brightness by up to +-amount with a hash of `key` (grain by grain).
Eigen::Vector3f vary(const Eigen::Vector3f& srgb, std::uint32_t key, float amount);

}  // namespace ts::preview
