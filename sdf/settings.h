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
  // Cap on the bounding grid (dims product). Nothing allocates the box: scan conversion works in
  // z-slabs bounded by --max-slab-mb and keeps only the band (the exact CPU path goes slice by slice),
  // so the cap only stops a resolution typed by mistake; 2^37 (about 5120^3) admits the 4096-class
  // grids of docs/benchmarks.md ("Sparse SDF memory") and the 2048-class previews.
  std::size_t max_voxels = std::size_t{1} << 37;
};

}  // namespace ts::sdf
