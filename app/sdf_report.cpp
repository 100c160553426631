#include "app/sdf_report.h"

#include <fmt/format.h>

#include <chrono>

#include <nlohmann/json.hpp>

#include "sdf/exact_sdf.h"
#include "sdf/openvdb_compare.h"

namespace ts::app {

void print_sdf_figures(const SdfOptions& o, const SdfFigures& f) {
  const double per = f.band_voxels ? 1.0 / static_cast<double>(f.band_voxels) : 0.0;
  fmt::print(
      "memory: {} band voxels; host level set {:.1f} MiB ({:.1f} bytes a band voxel), as NanoVDB {:.1f} MiB "
      "({:.1f} bytes a band voxel)",
      f.band_voxels, f.host_bytes / 1048576.0, static_cast<double>(f.host_bytes) * per,
      f.nanovdb_bytes / 1048576.0, static_cast<double>(f.nanovdb_bytes) * per);
  if (o.backend == "gpu") {
    fmt::print("; scan conversion {:.1f} MiB on the GPU at its peak, {:.1f} MiB read back",
               f.scan_gpu_bytes / 1048576.0, f.readback_bytes / 1048576.0);
  }
  fmt::print("\n");
}

void print_sdf_times(const SdfOptions& o, const sdf::ScanConvertStats& st, const SdfFigures& f) {
  if (o.backend == "gpu") {
    fmt::print(
        "times: scan conversion {:.3f} s (GPU {:.3f} s, read-back {:.3f} s, host build {:.3f} s on this "
        "thread; leaves built {:.3f} s beside the GPU), write {:.3f} s\n",
        st.seconds, st.gpu_seconds, st.readback_seconds, st.host_build_seconds, st.leaf_build_seconds,
        f.write_seconds);
  } else {
    fmt::print("times: exact SDF {:.3f} s, write {:.3f} s\n", st.seconds, f.write_seconds);
  }
}

namespace {

// The geometry path's pipeline statistics against the prism model (sdf --timings), null when not counted.
nlohmann::ordered_json pipeline_json(const sdf::ScanPipelineWork& p) {
  if (!p.measured) return nullptr;
  return {{"geometry_invocations", p.geometry_invocations}, {"model_invocations", p.model_invocations},
          {"drawn_prisms", p.drawn_prisms},
          {"geometry_primitives", p.geometry_primitives}, {"model_primitives", p.model_primitives},
          {"fragments", p.fragments}, {"model_prism_volume_voxels", p.model_volume}};
}

}  // namespace

void print_sdf_json(const SdfOptions& o, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                const sdf::ScanConvertStats& st, const SdfFigures& f, const std::string& device) {
  const nlohmann::ordered_json out = {
      {"mesh", o.mesh},
      {"output", o.output},
      {"triangles", mesh.triangle_count()},
      {"grid",
       {{"dims", {spec.dims.x(), spec.dims.y(), spec.dims.z()}},
        {"voxel_size", spec.voxel_size},
        {"band", o.band}}},
      {"band_voxels", f.band_voxels},
      {"host_bytes", f.host_bytes},
      {"host_bytes_per_band_voxel", f.band_voxels ? static_cast<double>(f.host_bytes) / f.band_voxels : 0.0},
      {"nanovdb_bytes", f.nanovdb_bytes},
      {"nanovdb_bytes_per_band_voxel",
       f.band_voxels ? static_cast<double>(f.nanovdb_bytes) / f.band_voxels : 0.0},
      {"scan_peak_gpu_bytes", f.scan_gpu_bytes},
      {"readback_bytes", f.readback_bytes},
      {"slabs", st.slabs},
      {"draws", st.draws},
      {"degenerate_triangles", st.degenerate_triangles},
      {"needle_triangles", st.needle_triangles},
      {"scan_seconds", f.scan_seconds},
      {"gpu_seconds", st.gpu_seconds},
      {"readback_seconds", st.readback_seconds},
      {"host_build_seconds", st.host_build_seconds},
      {"leaf_build_seconds", st.leaf_build_seconds},
      {"write_seconds", f.write_seconds},
      {"total_seconds", f.total_seconds},
      {"backend", o.backend},
      {"scan", o.backend == "cpu" ? nlohmann::ordered_json(nullptr)
                                  : nlohmann::ordered_json(sdf::scan_method_name(st.method))},
      {"scan_reason", o.backend == "cpu" ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(o.scan_reason)},
      {"brick_pairs", st.brick_pairs},
      {"pipeline", pipeline_json(st.pipeline)},
      {"renderer", device}};
  fmt::print("{}\n", out.dump(2));
}

void print_sdf_summary(const SdfOptions& o, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                   const sdf::ScanConvertStats& st) {
  fmt::print("{}: {} triangles -> {} ({} x {} x {} voxels of {:.6g}, band {} voxels, {} band voxels)\n", o.mesh,
             mesh.triangle_count(), o.output, spec.dims.x(), spec.dims.y(), spec.dims.z(), spec.voxel_size, o.band,
             st.band_voxels);
  if (st.degenerate_triangles || st.needle_triangles) {
    fmt::print("{} degenerate triangles skipped, {} needle triangles bounded by rectangles\n", st.degenerate_triangles,
               st.needle_triangles);
  }
  if (o.timings && o.backend == "gpu") {
    fmt::print("{} slabs of {} layers, {} draws, peak GPU memory {:.1f} MiB, {:.3f} s\n{}", st.slabs,
               st.layers_per_slab, st.draws, st.peak_gpu_bytes / 1048576.0, st.seconds, st.timing_report);
  }
  if (o.timings && st.pipeline.measured) {
    const sdf::ScanPipelineWork& p = st.pipeline;
    fmt::print("pipeline statistics (geometry path) against the prism model: {} geometry-shader invocations "
               "({} asked for by {} prisms), {} primitives emitted ({} by the model), {} fragments ({:.0f} voxel centres in "
               "the prisms; {:.2f} fragments a band voxel)\n",
               p.geometry_invocations, p.model_invocations, p.drawn_prisms, p.geometry_primitives, p.model_primitives, p.fragments,
               p.model_volume, st.band_voxels ? static_cast<double>(p.fragments) / st.band_voxels : 0.0);
  }
}

void print_sdf_comparison(const SdfOptions& o, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                      const sdf::ScanConvertResult& result) {
  auto lap = std::chrono::steady_clock::now();
  const auto exact_grid = sdf::exact_sdf_grid(mesh, spec, o.band, o.sign == "winding" ? sdf::SignMethod::Winding
                                                                                       : sdf::SignMethod::Pseudonormal);
  const double exact_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - lap).count();
  lap = std::chrono::steady_clock::now();
  const auto vdb = sdf::openvdb_level_set(mesh, spec.voxel_size, o.band);
  const double vdb_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - lap).count();
  fmt::print("times: tetrasand GPU {:.3f} s, CPU exact {:.3f} s, OpenVDB meshToLevelSet {:.3f} s\n", result.stats.seconds,
             exact_seconds, vdb_seconds);
  const double band_world = o.band * spec.voxel_size;
  fmt::print("{}", sdf::format_comparison(sdf::compare_grids(*result.grid, *exact_grid, spec.voxel_size, band_world),
                                          sdf::compare_grids(*vdb, *exact_grid, spec.voxel_size, band_world),
                                          sdf::compare_grids(*result.grid, *vdb, spec.voxel_size, band_world)));
}

}  // namespace ts::app
