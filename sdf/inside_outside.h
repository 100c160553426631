#pragma once
// Signs for the voxels outside the narrow band. Scan conversion only writes voxels near the surface;
// every other voxel of the grid is either deep inside or far outside, and which one follows from
// connectivity: a closed band (half-width >= 1/2 voxel) separates the grid into regions that no
// 6-connected path of non-band voxels crosses, so each region takes one sign.
//
// Dense layout: values[spec.linear_index(i, j, k)]. A voxel is in the band when its value is finite;
// kNotInBand (or any non-finite value) marks the voxels to classify.
#include <cstddef>
#include <limits>
#include <vector>

#include "sdf/grid.h"

namespace ts::sdf {

// The sentinel scan conversion leaves in voxels it did not reach.
inline constexpr float kNotInBand = std::numeric_limits<float>::infinity();

struct InsideOutsideStats {
  std::size_t outside_voxels = 0;  // set to +band
  std::size_t inside_voxels = 0;   // set to -band
  std::size_t regions = 0;         // 6-connected regions of non-band voxels
  std::size_t cavities = 0;        // regions away from the grid border whose band neighbours are mostly positive
};

// Replaces every non-finite value by +band_world (outside) or -band_world (inside) [m]:
//  - a region of non-band voxels that touches the grid border is outside (the grid pads the mesh's
//    bounding box, so the border is outside the mesh);
//  - any other region is inside, unless the band voxels next to it are mostly positive: then it is
//    a cavity (the hollow of a shell, a bubble) and outside.
// Memory: one byte per voxel plus the traversal stack. Band values are left untouched.
InsideOutsideStats fill_outside_band_signs(const GridSpec& spec, std::vector<float>& values, float band_world);

}  // namespace ts::sdf
