#pragma once
// What the user asks of an SDF: `tetrasand sdf --voxel H | --resolution N --band W --sign ...`.
#include <cstddef>

namespace ts::sdf {

enum class SignMethod {
  Pseudonormal,  // angle-weighted pseudonormals: exact for closed, consistently oriented meshes
  Winding,       // generalised winding number (Jacobson et al. 2013): robust to holes
};

struct SdfSettings {
  double voxel_size = 0.0;   // [m]; 0: the longest bounding-box side / resolution
  int resolution = 128;      // voxels along the longest side when voxel_size is 0
  double band = 3.0;         // half-width of the narrow band [voxels]
  int padding = -1;          // voxels beyond the bounding box; -1: ceil(band) + 1
  SignMethod sign = SignMethod::Pseudonormal;
  std::size_t max_voxels = std::size_t{1} << 31;  // cap on the bounding grid (dims product)
};

}  // namespace ts::sdf
