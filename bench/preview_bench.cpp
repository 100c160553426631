// Preview rendering times (docs/benchmarks.md, "preview"): an image of a large SDF (ray casting), of
// many particle impostors, and of both (the hybrid), each with the shadow map, on whatever device
// the context picks, by the draws (raster), the compute kernels (compute) or both in one run (the
// default: same device, same scene, so the two rows compare). The SDF is OpenVDB's meshToLevelSet of
// the mesh (CPU, so the figure is the renderer's, not the scan conversion's), as a sparse NanoVDB grid,
// as `tetrasand preview SDF.vdb` reads it. Usage:
//   tetrasand_bench_preview [MESH] [--size 1024] [--resolution 512] [--particles 1000000] [--repeat 3]
//                           [--gpu-path raster|compute|both] [--png PREFIX]
// --png writes the last SDF, hybrid and impostor images as PREFIX-<path>-{sdf,hybrid,impostors}.png.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <string>
#include <vector>

#include "core/mesh_io.h"
#include "gpu/context.h"
#include "preview/image.h"
#include "preview/renderer.h"
#include "preview/volume.h"
#include "sampler/surface_points.h"
#include "sdf/openvdb_compare.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Timing {
  double first = 0.0, median = 0.0;  // s: the first render (allocations, shader warm-up) and the median of the rest
  ts::preview::Image last;
};

Timing time_renders(ts::preview::Renderer& renderer, const ts::preview::RenderSettings& settings, int repeat) {
  Timing t;
  std::vector<double> times;
  for (int k = 0; k <= repeat; ++k) {
    ts::preview::RenderResult result = renderer.render(settings);
    const double s = result.seconds;  // render() reads the image back: the work is finished
    t.last = std::move(result.image);
    if (k == 0) {
      t.first = s;
    } else {
      times.push_back(s);
    }
  }
  std::sort(times.begin(), times.end());
  t.median = times.empty() ? t.first : times[times.size() / 2];
  return t;
}

struct Options {
  std::string mesh_path = TETRASAND_SOURCE_DIR "/assets/bunny.obj";
  int size = 1024, resolution = 512, repeat = 3;
  std::string png_prefix, gpu_path = "both";
  std::size_t particle_count = 1'000'000;
};

// false for an unknown argument.
bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (a == "--size") {
      o.size = std::stoi(next());
    } else if (a == "--resolution") {
      o.resolution = std::stoi(next());
    } else if (a == "--particles") {
      o.particle_count = std::stoull(next());
    } else if (a == "--repeat") {
      o.repeat = std::stoi(next());
    } else if (a == "--png") {
      o.png_prefix = next();
    } else if (a == "--gpu-path") {
      o.gpu_path = next();
      if (o.gpu_path != "both" && !ts::preview::parse_gpu_path(o.gpu_path)) return false;
    } else if (!a.empty() && a[0] != '-') {
      o.mesh_path = a;
    } else {
      return false;
    }
  }
  return true;
}

// The three scenes by one path: the SDF alone and the hybrid in one renderer, the impostors alone in another.
void measure(const Options& o, ts::gpu::Context& context, const openvdb::FloatGrid& level_set,
             const ts::preview::Particles& particles, ts::preview::GpuPath path) {
  const char* name = ts::preview::gpu_path_name(path);
  ts::preview::Renderer renderer(context, true), particles_only(context, true);
  renderer.set_gpu_path(path);
  particles_only.set_gpu_path(path);
  renderer.set_volume(ts::preview::volume_from_level_set(level_set, o.mesh_path));
  ts::preview::RenderSettings s;
  s.width = s.height = o.size;
  s.camera = ts::preview::frame_box(renderer.content_box(), ts::preview::view_direction(ts::preview::View::Iso, s.up),
                                    s.up, 1.0, false, 30.0);
  const Timing sdf_only = time_renders(renderer, s, o.repeat);
  renderer.set_particles(particles);
  const Timing hybrid = time_renders(renderer, s, o.repeat);
  particles_only.set_particles(particles);
  const Timing impostors = time_renders(particles_only, s, o.repeat);
  if (!o.png_prefix.empty()) {
    const std::string prefix = o.png_prefix + "-" + name;
    ts::preview::write_png(prefix + "-sdf.png", sdf_only.last);
    ts::preview::write_png(prefix + "-hybrid.png", hybrid.last);
    ts::preview::write_png(prefix + "-impostors.png", impostors.last);
  }
  fmt::print("| image {0} x {0}, --gpu-path {2} | first render [s] | median of {1} [s] |\n|---|---:|---:|\n", o.size,
             o.repeat, name);
  fmt::print("| SDF {}^3-class ray cast | {:.3f} | {:.3f} |\n", o.resolution, sdf_only.first, sdf_only.median);
  fmt::print("| {} particle impostors | {:.3f} | {:.3f} |\n", o.particle_count, impostors.first, impostors.median);
  fmt::print("| hybrid: both | {:.3f} | {:.3f} |\n\n", hybrid.first, hybrid.median);
  fmt::print("per-pass GPU time ({}), all renders of the SDF and the hybrid:\n{}\n", name, renderer.timing_report());
  fmt::print("per-pass GPU time ({}), all renders of the impostors:\n{}\n", name, particles_only.timing_report());
}

int run(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) {
    fmt::print(stderr, "usage: tetrasand_bench_preview [MESH] [--size N] [--resolution N] [--particles N] [--repeat N] "
                       "[--gpu-path raster|compute|both] [--png PREFIX]\n");
    return 2;
  }
  const ts::TriangleMesh mesh = ts::load_mesh(o.mesh_path);
  ts::gpu::Context context;

  // The SDF: OpenVDB level set, as a sparse NanoVDB grid.
  auto t = Clock::now();
  const double h = ts::bounding_box(mesh).size().maxCoeff() / o.resolution;
  const auto grid = ts::sdf::openvdb_level_set(mesh, h, 3.0);
  const ts::preview::SdfVolume volume = ts::preview::volume_from_level_set(*grid, o.mesh_path);
  const double build = since(t);
  const Eigen::Vector3i d = volume.spec.dims;

  // The particles: area-uniform on the mesh, sized to cover it.
  std::mt19937_64 rng(1);
  const auto points = ts::sampler::sample_surface_points(mesh, o.particle_count, rng);
  ts::preview::Particles particles;
  particles.centers = points.positions;
  particles.radii = {static_cast<float>(1.2 * std::sqrt(ts::surface_area(mesh) / (3.14159 * o.particle_count)))};

  fmt::print("renderer: {}\n", context.summary());
  fmt::print("mesh {}: SDF {} x {} x {} voxels (sparse NanoVDB: {} band voxels, {:.1f} MiB on the GPU, against "
             "{:.1f} MiB for a dense R32F texture; built by OpenVDB in {:.2f} s), "
             "{} particles of radius {:.3g} m, images {} x {}, shadow map {} texels\n\n",
             o.mesh_path, d.x(), d.y(), d.z(), volume.band_voxels, volume.grid.size() / 1048576.0,
             volume.spec.voxel_count() * 4.0 / 1048576.0, build, o.particle_count, particles.radii[0], o.size, o.size,
             std::clamp(o.size, 512, 4096));
  for (ts::preview::GpuPath path : {ts::preview::GpuPath::Raster, ts::preview::GpuPath::Compute}) {
    if (o.gpu_path == "both" || o.gpu_path == ts::preview::gpu_path_name(path)) measure(o, context, *grid, particles, path);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    // A clear line and exit 1 (scripts/device-bench.sh records it as the part's error), not an abort.
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
}
