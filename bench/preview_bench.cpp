// Preview rendering times (docs/benchmarks.md, "preview"): an image of a large SDF (ray casting), of
// many particle impostors, and of both (the hybrid), each with the shadow map, on whatever device
// the context picks. The SDF is OpenVDB's meshToLevelSet of the mesh (CPU, so the figure is the
// renderer's, not the scan conversion's), as a sparse NanoVDB grid, as `tetrasand preview SDF.vdb` reads it. Usage:
//   tetrasand_bench_preview [MESH] [--size 1024] [--resolution 512] [--particles 1000000] [--repeat 3] [--png PREFIX]
// --png writes the last SDF, hybrid and impostor images as PREFIX-{sdf,hybrid,impostors}.png, to look at.
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

int run(int argc, char** argv) {
  std::string mesh_path = TETRASAND_SOURCE_DIR "/assets/bunny.obj";
  int size = 1024, resolution = 512, repeat = 3;
  std::string png_prefix;
  std::size_t particle_count = 1'000'000;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (a == "--size") {
      size = std::stoi(next());
    } else if (a == "--resolution") {
      resolution = std::stoi(next());
    } else if (a == "--particles") {
      particle_count = std::stoull(next());
    } else if (a == "--repeat") {
      repeat = std::stoi(next());
    } else if (a == "--png") {
      png_prefix = next();
    } else if (!a.empty() && a[0] != '-') {
      mesh_path = a;
    } else {
      fmt::print(stderr, "usage: tetrasand_bench_preview [MESH] [--size N] [--resolution N] [--particles N] [--repeat N] [--png PREFIX]\n");
      return 2;
    }
  }
  const ts::TriangleMesh mesh = ts::load_mesh(mesh_path);
  ts::gpu::Context context;
  ts::preview::Renderer renderer(context, true);

  // The SDF: OpenVDB level set, as a sparse NanoVDB grid.
  auto t = Clock::now();
  const double h = ts::bounding_box(mesh).size().maxCoeff() / resolution;
  const auto grid = ts::sdf::openvdb_level_set(mesh, h, 3.0);
  ts::preview::SdfVolume volume = ts::preview::volume_from_level_set(*grid, mesh_path);
  const double build = since(t);
  const Eigen::Vector3i d = volume.spec.dims;
  const std::size_t band_voxels = volume.band_voxels;
  const double sparse_mib = volume.grid.size() / 1048576.0;
  const double dense_mib = volume.spec.voxel_count() * 4.0 / 1048576.0;
  t = Clock::now();
  renderer.set_volume(std::move(volume));
  const double upload = since(t);

  // The particles: area-uniform on the mesh, sized to cover it.
  std::mt19937_64 rng(1);
  const auto points = ts::sampler::sample_surface_points(mesh, particle_count, rng);
  ts::preview::Particles particles;
  particles.centers = points.positions;
  particles.radii = {static_cast<float>(1.2 * std::sqrt(ts::surface_area(mesh) / (3.14159 * particle_count)))};

  ts::preview::RenderSettings s;
  s.width = s.height = size;
  s.camera = ts::preview::frame_box(renderer.content_box(), ts::preview::view_direction(ts::preview::View::Iso, s.up),
                                    s.up, 1.0, false, 30.0);
  const Timing sdf_only = time_renders(renderer, s, repeat);
  renderer.set_particles(particles);
  const Timing hybrid = time_renders(renderer, s, repeat);
  ts::preview::Renderer particles_only(context, true);
  particles_only.set_particles(particles);
  const Timing impostors = time_renders(particles_only, s, repeat);

  if (!png_prefix.empty()) {
    ts::preview::write_png(png_prefix + "-sdf.png", sdf_only.last);
    ts::preview::write_png(png_prefix + "-hybrid.png", hybrid.last);
    ts::preview::write_png(png_prefix + "-impostors.png", impostors.last);
  }
  fmt::print("renderer: {}\n", context.summary());
  fmt::print("mesh {}: SDF {} x {} x {} voxels (sparse NanoVDB: {} band voxels, {:.1f} MiB on the GPU, against "
             "{:.1f} MiB for a dense R32F texture; {} storage block(s); built by OpenVDB in {:.2f} s, uploaded in {:.2f} s), "
             "{} particles of radius {:.3g} m, images {} x {}, shadow map {} texels\n\n",
             mesh_path, d.x(), d.y(), d.z(), band_voxels, sparse_mib, dense_mib, renderer.field_chunks(), build, upload, particle_count,
             particles.radii[0], size, size, std::clamp(size, 512, 4096));
  fmt::print("| image {0} x {0} | first render [s] | median of {1} [s] |\n|---|---:|---:|\n", size, repeat);
  fmt::print("| SDF {}^3-class ray cast | {:.3f} | {:.3f} |\n", resolution, sdf_only.first, sdf_only.median);
  fmt::print("| {} particle impostors | {:.3f} | {:.3f} |\n", particle_count, impostors.first, impostors.median);
  fmt::print("| hybrid: both | {:.3f} | {:.3f} |\n\n", hybrid.first, hybrid.median);
  fmt::print("per-pass GPU time, all renders of the SDF and the hybrid:\n{}\n", renderer.timing_report());
  fmt::print("per-pass GPU time, all renders of the impostors:\n{}", particles_only.timing_report());
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
