#pragma once
// What `tetrasand sdf` prints: the summary line, the memory figures (--timings), the JSON report (--json)
// and the comparison with the exact SDF and OpenVDB (--compare-openvdb). app/cmd_sdf.cpp holds the
// options and the run; the reports live here.
#include <cstddef>
#include <string>

#include "core/mesh.h"
#include "sdf/grid.h"
#include "sdf/scan_convert.h"

namespace ts::app {

// The command line of `tetrasand sdf`.
struct SdfOptions {
  std::string mesh, output;
  double voxel = 0;
  int resolution = 128;
  double band = 3.0;
  int padding = -1;
  std::string sign = "pseudonormal";
  std::string backend = "auto";  // gpu: scan conversion; cpu: the exact SDF (sdf/exact_sdf.h); auto: the rule
  std::string scan = "auto";     // the scan method (sdf::parse_scan_method): compute, geometry or auto
  std::string scan_reason;       // on the GPU path, once auto is resolved: why (sdf::ScanChoice::reason)
  double scale = 1.0;
  double slab_mb = 1024;
  std::string nvdb_codec = "zip";  // .nvdb output only: sdf::parse_nvdb_codec
  bool timings = false, compare = false, json = false;
};

// What the run cost: the band, memory per band voxel, host traffic (--timings, --json).
struct SdfFigures {
  std::size_t band_voxels = 0;
  std::size_t host_bytes = 0;       // the OpenVDB level set on the host
  std::size_t nanovdb_bytes = 0;    // the same as a NanoVDB grid: what a GPU field of it takes
  std::size_t scan_gpu_bytes = 0;   // scan conversion's slab target and buffers at their peak
  std::size_t readback_bytes = 0;   // GPU -> host during scan conversion
  double scan_seconds = 0.0, total_seconds = 0.0;
  double write_seconds = 0.0;  // the output file (for .nvdb the conversion to NanoVDB with it)
};

// One line a run: mesh, triangles, output, grid, band voxels (and degenerate and needle triangles,
// and the slab table with --timings on the GPU path).
void print_sdf_summary(const SdfOptions& o, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                       const sdf::ScanConvertStats& st);
// The times line of --timings: the scan conversion split into GPU, read-back and host build (GPU
// path), and the write.
void print_sdf_times(const SdfOptions& o, const sdf::ScanConvertStats& st, const SdfFigures& f);
// The memory line of --timings.
void print_sdf_figures(const SdfOptions& o, const SdfFigures& f);
// The --json report on standard output.
void print_sdf_json(const SdfOptions& o, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                    const sdf::ScanConvertStats& st, const SdfFigures& f, const std::string& device);
// --compare-openvdb: the exact SDF and OpenVDB's meshToLevelSet on the same grid, timed, and all three
// fields compared.
void print_sdf_comparison(const SdfOptions& o, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                          const sdf::ScanConvertResult& result);

}  // namespace ts::app
