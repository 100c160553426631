#pragma once
// What the user asks of an SDF: `tetrasand sdf --voxel H | --resolution N --band W --sign ...`.
#include <cstddef>
#include <optional>
#include <string_view>

namespace ts::sdf {

enum class SignMethod {
  Pseudonormal,  // angle-weighted pseudonormals: exact for closed, consistently oriented meshes
  Winding,       // generalised winding number (Jacobson et al. 2013): robust to holes
};

// How the triangles reach the voxels. Geometry: the thesis's method, each triangle's prism sliced by a
// geometry shader and rasterised, the depth test keeping the nearest (fast where the raster hardware
// is). Compute: triangle/brick pairs and per-brick triangle lists in compute shaders
// (sdf/compute_scan.h), which use the whole GPU. Both give every band voxel its exact float distance and the same signs; compute
// breaks ties by the lower triangle index, so its bytes never depend on the order work runs in.
enum class ScanMethod { Geometry, Compute };

// "geometry", "compute": the --scan spellings.
inline const char* scan_method_name(ScanMethod method) {
  return method == ScanMethod::Compute ? "compute" : "geometry";
}
// The --scan spellings "compute", "geometry" and "auto"; nullopt for any other text. Auto reads as
// Compute here; the commands resolve it first by sdf::choose_scan (sdf/scan_calibration.h), which
// takes Geometry where a calibration on this renderer and driver found it faster.
inline std::optional<ScanMethod> parse_scan_method(std::string_view text) {
  if (text == "compute" || text == "auto") return ScanMethod::Compute;
  if (text == "geometry") return ScanMethod::Geometry;
  return std::nullopt;
}

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
