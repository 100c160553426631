#include "preview/body_preview.h"

#include <chrono>
#include <memory>

#include "preview/cpu_renderer.h"
#include "preview/path_calibration.h"
#include "preview/renderer.h"

namespace ts::preview {

BodyPreviewReport write_body_preview(gpu::Context* context, const TriangleMesh& mesh, const body::ParticleBody& body,
                                     const std::filesystem::path& png, const std::vector<std::filesystem::path>& inputs,
                                     const BodyPreviewSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  BodyPreviewReport report;
  std::unique_ptr<ImageRenderer> drawn;
  if (context) {
    const GpuPathChoice path = choose_gpu_path(*context, GpuPath::Auto);
    auto gl = std::make_unique<Renderer>(*context);
    gl->set_gpu_path(path.path);
    report.gpu_path = path.describe();
    drawn = std::move(gl);
  } else {
    drawn = std::make_unique<CpuRenderer>();
  }
  ImageRenderer& renderer = *drawn;
  sdf::SdfSettings grid;
  grid.resolution = settings.resolution;
  grid.sign = settings.sign;
  SdfVolume volume = context ? volume_from_mesh(*context, mesh, grid) : volume_from_mesh_on_cpu(mesh, grid);
  report.field_drawn = !volume.inside_out() || body.positions.empty();
  if (report.field_drawn) renderer.load_volume(std::move(volume));
  Particles particles;
  for (const auto& p : body.positions) particles.centers.push_back(p.cast<double>());
  particles.radii = {static_cast<float>(body.particle_radius)};
  if (!particles.centers.empty()) renderer.set_particles(particles);

  RenderSettings s;
  s.width = settings.width;
  s.height = settings.height;
  s.up = settings.up.normalized();
  s.camera = frame_box(renderer.content_box(), view_direction(View::Iso, s.up), view_image_up(View::Iso, s.up),
                       static_cast<double>(s.width) / s.height, false, 30.0);
  write_png(png, renderer.render(s).image, inputs);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace ts::preview
