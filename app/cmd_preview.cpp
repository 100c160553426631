// `tetrasand preview (MESH | SDF.vdb | SDF.nvdb) [--particles FILE] -o OUT.png`: off-screen ray-cast preview.
#include <fmt/format.h>

#include <cctype>
#include <memory>
#include <numbers>
#include <optional>
#include <regex>

#include "app/commands.h"
#include "app/numeric_options.h"
#include "app/preview_report.h"
#include "app/progress.h"
#include "core/error.h"
#include "core/log.h"
#include "core/mesh_io.h"
#include "core/mesh_report.h"
#include "gpu/backend.h"
#include "preview/camera.h"
#include "preview/cpu_renderer.h"
#include "preview/image.h"
#include "preview/inputs.h"
#include "preview/path_calibration.h"
#include "preview/renderer.h"
#include "preview/volume.h"
#include "sampler/point_grid.h"
#include "sdf/exact_sdf.h"
#include "sdf/vdb_io.h"

namespace ts::app {
namespace {

struct Options {
  std::string input, output, particles, size = "800x800", view = "iso", color_by = "none";
  std::string backend = "auto";  // where the picture is drawn (gpu/backend.h's rule)
  std::string sign;               // MESH: pseudonormal (the default) or winding
  std::string gpu_path = "auto";  // the GPU renderer's shadow map and G-buffer: draws or compute kernels
  std::vector<double> eye, target, up{0.0, 0.0, 1.0}, light;
  double fov = 30.0, particle_radius = 0.0, color_max = 0.0, voxel = 0.0, band = 3.0, scale = 1.0;
  int resolution = 192, turntable = 1;
  bool ortho = false, contact_sheet = false, alpha = false, no_ground = false, no_shadows = false, timings = false;
  bool json = false;  // the report as JSON on standard output instead of the summary
};

Eigen::Vector3d vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

Eigen::Vector2i parse_size(const std::string& text) {
  static const std::regex pattern(R"(\s*(\d{1,9})\s*[xX]\s*(\d{1,9})\s*)");
  std::smatch m;
  if (!std::regex_match(text, m, pattern)) {
    throw InputError("--size '" + text + "': expected WIDTHxHEIGHT in pixels, e.g. 800x600");
  }
  return {std::stoi(m[1].str()), std::stoi(m[2].str())};
}

bool is_vdb(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".vdb" || ext == ".nvdb";
}

// OUT.png -> OUT_007.png for turntable frame 7.
std::filesystem::path numbered(const std::filesystem::path& out, int frame, int frames) {
  const int digits = std::max(3, static_cast<int>(std::to_string(frames - 1).size()));
  return out.parent_path() / fmt::format("{}_{:0{}d}{}", out.stem().string(), frame, digits, out.extension().string());
}

preview::Camera make_camera(const Options& o, const Aabb& box, double aspect) {
  const Eigen::Vector3d up = vec3(o.up);
  if (!o.eye.empty()) {
    preview::Camera c;
    c.eye = vec3(o.eye);
    c.target = o.target.empty() ? box.center() : vec3(o.target);
    c.up = up;
    c.fov_y = o.fov;
    c.ortho = o.ortho;
    preview::validate(c);
    if (c.ortho) {
      const preview::Camera fitted = preview::frame_box(box, c.eye - c.target, up, aspect, true, o.fov, o.turntable, up);
      c.ortho_height = fitted.ortho_height;
    }
    return c;
  }
  const preview::View view = preview::parse_view(o.view);
  return preview::frame_box(box, preview::view_direction(view, up), preview::view_image_up(view, up), aspect, o.ortho,
                            o.fov, o.turntable, up);
}

// Options are registered in the order --help lists them.
void add_input_options(CLI::App* cmd, Options& o) {
  cmd->add_option("INPUT", o.input, "Mesh (any format assimp reads; scan-converted here) or a level set SDF.vdb or SDF.nvdb");
  cmd->add_option("-o,--output", o.output, "Output PNG")->required();
  cmd->add_option("--particles", o.particles, "Particles over the surface: NAME.body.json or a PLY of centres");
  cmd->add_option("--particle-radius", o.particle_radius,
                  "Particle radius [m] (default: the body.json's, else half the median neighbour distance)")
      ->check(positive());
  cmd->add_option("--size", o.size, "Image size WIDTHxHEIGHT [pixels]")->capture_default_str();
  cmd->add_option("--backend", o.backend,
                  "gpu: the GL renderer; cpu: OpenVDB's level-set ray intersector and a sphere splatter on every "
                  "core, the field of a MESH by the exact SDF (no GL context); auto: cpu on a software renderer "
                  "such as llvmpipe, else gpu")
      ->check(CLI::IsMember({"auto", "gpu", "cpu"}))
      ->capture_default_str();
  cmd->add_option("--gpu-path", o.gpu_path,
                  "On the GPU, the shadow map and G-buffer by draws (raster) or by compute kernels (compute); "
                  "auto: whichever a calibration on this GL device found faster (timed once, cached), compute on a tie")
      ->check(CLI::IsMember({"auto", "raster", "compute"}))
      ->capture_default_str();
}

// Where the camera is and how it turns.
void add_camera_options(CLI::App* cmd, Options& o) {
  cmd->add_option("--view", o.view, "Named view relative to --up: front, side, top or iso")
      ->check(CLI::IsMember({"front", "side", "top", "iso"}))
      ->capture_default_str();
  auto* eye = cmd->add_option("--eye", o.eye, "Camera position X,Y,Z [m] (instead of --view)")
                  ->delimiter(',')
                  ->expected(3)
                  ->check(finite());
  cmd->add_option("--target", o.target, "Point looked at X,Y,Z [m] (default: the centre of what is drawn)")
      ->delimiter(',')
      ->expected(3)
      ->check(finite())
      ->needs(eye);
  cmd->add_option(
         "--up", o.up,
         "World up X,Y,Z: the ground's normal and the image's up (+z, as in the simulator; `info` tells a "
         "mesh's tallest axis)")
      ->delimiter(',')
      ->expected(3)
      ->check(finite())
      ->capture_default_str();
  cmd->add_option("--fov", o.fov, "Vertical field of view [degrees]")->check(finite())->capture_default_str();
  cmd->add_flag("--ortho", o.ortho, "Orthographic lens (framed to fit)");
  cmd->add_option("--turntable", o.turntable,
                  "N views turning about --up: OUT_000.png ... (or one --contact-sheet)")
      ->check(int_range(1, 10000));
  cmd->add_flag("--contact-sheet", o.contact_sheet, "With --turntable: tile all views into OUT.png");
}

void add_colour_options(CLI::App* cmd, Options& o) {
  cmd->add_flag("--alpha", o.alpha, "Transparent background; the ground shows only its shadows");
  cmd->add_option(
         "--color-by", o.color_by,
         "Colour the surface by: none, error (distance from the mesh, voxels; MESH input) or "
         "particle-distance (distance to the nearest particle centre, in radii of the body, whatever "
         "--particle-radius draws)")
      ->check(CLI::IsMember({"none", "error", "particle-distance"}))
      ->capture_default_str();
  cmd->add_option("--color-max", o.color_max,
                  "Value at the top of the colour map (default 0.25 voxel / 1.5 radii)")
      ->check(positive());
}

// How a MESH input is scan-converted.
void add_sdf_options(CLI::App* cmd, Options& o) {
  auto* voxel = cmd->add_option("--voxel", o.voxel, "MESH: SDF voxel size [m]")->check(positive());
  cmd->add_option("--resolution", o.resolution, "MESH: SDF voxels along the longest side")
      ->check(positive())
      ->excludes(voxel)
      ->capture_default_str();
  cmd->add_option("--band", o.band, "MESH: narrow-band half-width [voxels], >= 2 for clean normals")
      ->check(finite())
      ->capture_default_str();
  cmd->add_option("--sign", o.sign,
                  "MESH: inside/outside by pseudonormals (closed meshes; default) or by the generalised winding "
                  "number (also open or non-manifold meshes), as `sdf --sign` and `sample --sign`")
      ->check(CLI::IsMember({"pseudonormal", "winding"}));
  cmd->add_option("--scale", o.scale, "MESH and particles: multiply coordinates by this factor first")
      ->check(positive());
}

void add_lighting_options(CLI::App* cmd, Options& o) {
  cmd->add_option("--light", o.light,
                  "Direction towards the key light X,Y,Z (default: upper left, behind the camera)")
      ->delimiter(',')
      ->expected(3)
      ->check(finite());
  cmd->add_flag("--no-ground", o.no_ground, "No ground plane");
  cmd->add_flag("--no-shadows", o.no_shadows, "No shadow map");
  cmd->add_flag("--timings", o.timings, "Per-pass times (GPU timer queries, or wall time on the CPU)");
  cmd->add_flag("--json", o.json,
                "Print the report (inputs, PNGs written, image size, backend and device, what was drawn, "
                "per-pass times) as JSON on standard output");
}

// Combinations CLI11 cannot check by itself.
void check_options(const Options& o) {
  if (o.input.empty() && o.particles.empty()) throw Error(ExitCode::Usage, "preview: give a MESH or an SDF.vdb / SDF.nvdb, or --particles");
  if (o.contact_sheet && o.turntable < 2) throw Error(ExitCode::Usage, "--contact-sheet needs --turntable N with N >= 2");
  if (o.color_by == "error" && (o.input.empty() || is_vdb(o.input))) {
    throw InputError("--color-by error needs a MESH input: the exact distance comes from the mesh");
  }
  if (!o.sign.empty() && (o.input.empty() || is_vdb(o.input))) {
    throw InputError("--sign needs a MESH input: a level set carries its own signs");
  }
  if (o.color_by == "particle-distance" && o.particles.empty()) {
    throw InputError("--color-by particle-distance needs --particles");
  }
}

preview::SdfVolume volume_from_vdb(const Options& o) {
  preview::SdfVolume volume = preview::volume_from_level_set(*sdf::read_level_set(o.input), o.input);
  if (volume.band < 2.0) {
    log::warn("{}: the narrow band is {:.3g} voxels; below 2 the surface normals may show steps", o.input, volume.band);
  }
  return volume;
}

// The field is built where the picture is drawn: scan-converted on the GL device, or the exact SDF on
// the CPU (no context).
preview::SdfVolume volume_from_mesh_file(const Options& o, gpu::Context* context, std::optional<TriangleMesh>& mesh) {
  mesh = load_mesh(o.input);
  if (o.scale != 1.0) scale_mesh(*mesh, o.scale);
  ReportOptions report_options;
  report_options.self_intersections = false;
  const MeshReport report = analyze_mesh(*mesh, report_options);
  const bool winding = o.sign == "winding";
  if (!report.closed() && !winding) {
    log::warn("{}: the mesh is not closed ({}); pseudonormal signs may be wrong near the holes: use --sign winding",
              o.input, closed_solid_problems(report));
  }
  if (o.band < 2.0) throw InputError(fmt::format("--band {}: the preview needs a band of at least 2 voxels", o.band));
  sdf::SdfSettings grid;
  grid.voxel_size = o.voxel;
  grid.resolution = o.resolution;
  grid.band = o.band;
  grid.sign = winding ? sdf::SignMethod::Winding : sdf::SignMethod::Pseudonormal;
  return naming_file(o.input, [&] {
    return context ? preview::volume_from_mesh(*context, *mesh, grid) : preview::volume_from_mesh_on_cpu(*mesh, grid);
  });
}

// What the picture shows and how it is coloured, kept alive while it renders.
struct Content {
  std::optional<TriangleMesh> mesh;  // MESH input only
  double voxel_size = 0.0;           // m, of the SDF (0 without one)
  std::string field;                 // what the SDF is, for the summary
  preview::LoadedParticles loaded;
  std::unique_ptr<sdf::ExactDistance> exact;
  std::unique_ptr<sampler::PointGrid> particle_grid;
  std::string scalar_name;
  std::vector<std::filesystem::path> inputs;
};

// `context`: the GL device's when the GPU draws, else null.
void load_field(const Options& o, gpu::Context* context, preview::ImageRenderer& renderer, Content& content) {
  if (o.input.empty()) return;
  content.inputs.emplace_back(o.input);
  preview::SdfVolume volume = is_vdb(o.input) ? volume_from_vdb(o) : volume_from_mesh_file(o, context, content.mesh);
  content.voxel_size = volume.spec.voxel_size;
  content.field = fmt::format("SDF {} x {} x {} voxels of {:.4g} m (band {:.3g}; sparse: {} band voxels, {:.1f} MiB)",
                              volume.spec.dims.x(), volume.spec.dims.y(), volume.spec.dims.z(), content.voxel_size,
                              volume.band, volume.band_voxels, volume.grid.size() / 1048576.0);
  if (volume.inside_out()) {
    // Ray-cast, this field is a solid box hiding everything: say so, draw the particles alone.
    const std::string why = fmt::format(
        "the SDF reads inside at the corner of its box, so its signs are unreliable ({}) and it is not drawn",
        is_vdb(o.input) ? "an inverted sign convention, or a flood fill that leaked through a hole"
                        : "an open mesh under pseudonormal signs? --sign winding signs it by the winding number");
    if (o.particles.empty()) throw InputError(o.input, why + "; nothing else to draw");
    log::warn("{}: {}", o.input, why);
    content.field += "; NOT drawn: signs unreliable (inside at the box's corner)";
    content.voxel_size = 0.0;
    return;
  }
  renderer.load_volume(std::move(volume));
}

void load_particles(const Options& o, preview::ImageRenderer& renderer, Content& content) {
  if (o.particles.empty()) return;
  content.inputs.emplace_back(o.particles);
  content.loaded = preview::load_particles(o.particles, o.particle_radius);
  if (o.scale != 1.0) {
    for (auto& c : content.loaded.particles.centers) c *= o.scale;
    if (o.particle_radius <= 0.0) content.loaded.particles.radii[0] *= static_cast<float>(o.scale);
    content.loaded.sampled_radius *= o.scale;
  }
  renderer.set_particles(content.loaded.particles);
}

// --color-by: the scalar each visible surface pixel is coloured by.
void set_surface_colouring(const Options& o, Content& content, preview::RenderSettings& settings) {
  if (o.color_by == "error") {
    content.exact = std::make_unique<sdf::ExactDistance>(*content.mesh);
    settings.surface_scalar.value = [exact = content.exact.get(), voxel_size = content.voxel_size](const Eigen::Vector3d& p) {
      return exact->closest(p).distance / voxel_size;
    };
    settings.surface_scalar.max_value = o.color_max > 0 ? o.color_max : 0.25;
    content.scalar_name = "distance from the rendered surface to the mesh [voxels]";
  } else if (o.color_by == "particle-distance") {
    // In radii the set was sampled for, not the drawing radius (--particle-radius would saturate it).
    const double r = content.loaded.sampled_radius > 0.0 ? content.loaded.sampled_radius
                                                         : content.loaded.particles.radii[0];
    content.particle_grid = std::make_unique<sampler::PointGrid>(content.loaded.particles.centers, 2.0 * r);
    settings.surface_scalar.value = [grid = content.particle_grid.get(), r](const Eigen::Vector3d& p) {
      return grid->nearest(p).distance / r;
    };
    settings.surface_scalar.max_value = o.color_max > 0 ? o.color_max : 1.5;
    content.scalar_name =
        fmt::format("distance from the surface to the nearest particle centre [radii of {:.4g} m]", r);
  }
}

void set_lighting(const Options& o, const Eigen::Vector2i& size, preview::RenderSettings& settings) {
  settings.width = size.x();
  settings.height = size.y();
  settings.up = vec3(o.up);
  if (!(settings.up.norm() > 0.0)) throw InputError("--up must not be the zero vector");
  if (!o.light.empty()) settings.light = vec3(o.light);
  settings.alpha = o.alpha;
  settings.ground = !o.no_ground;
  settings.shadows = !o.no_shadows;
}

struct Views {
  double seconds = 0.0;  // s, render time of all views
  preview::ScalarSummary scalar;
};

// The turntable's views, written one PNG each or tiled into one contact sheet.
Views render_views(const Options& o, preview::ImageRenderer& renderer, preview::RenderSettings& settings,
                   const preview::Camera& camera, const std::vector<std::filesystem::path>& inputs) {
  std::vector<preview::Image> sheet;
  Views views;
  Progress progress;  // a turntable of many views on llvmpipe takes minutes: say which view is drawn
  for (int k = 0; k < o.turntable; ++k) {
    if (o.turntable > 1) progress.update(fmt::format("view {} of {}", k + 1, o.turntable), static_cast<double>(k) / o.turntable);
    settings.camera = preview::orbit(camera, settings.up, 2.0 * std::numbers::pi * k / o.turntable);
    preview::RenderResult result = renderer.render(settings);
    views.seconds += result.seconds;
    views.scalar.pixels += result.scalar.pixels;
    views.scalar.mean += result.scalar.mean * static_cast<double>(result.scalar.pixels);
    views.scalar.max = std::max(views.scalar.max, result.scalar.max);
    if (o.contact_sheet) {
      sheet.push_back(std::move(result.image));
    } else {
      const std::filesystem::path out = o.turntable > 1 ? numbered(o.output, k, o.turntable) : std::filesystem::path(o.output);
      preview::write_png(out, result.image, inputs);
    }
  }
  progress.end();
  if (o.contact_sheet) preview::write_png(o.output, preview::contact_sheet(sheet), inputs);
  return views;
}

void print_summary(const Options& o, const Eigen::Vector2i& size, const Content& content, const Views& views,
                   const preview::RenderSettings& settings, const preview::ImageRenderer& renderer) {
  std::string what = content.field;
  const preview::Particles& particles = content.loaded.particles;
  if (!particles.centers.empty()) {
    what += fmt::format("{}{} particles of radius {:.4g} m ({})", what.empty() ? "" : ", ", particles.centers.size(),
                        particles.radii[0], content.loaded.radius_source);
  }
  const std::string files = o.turntable > 1 && !o.contact_sheet
                                ? fmt::format("{} .. {}", numbered(o.output, 0, o.turntable).string(),
                                              numbered(o.output, o.turntable - 1, o.turntable).string())
                                : o.output;
  fmt::print("{} -> {} ({} x {}{})\n", o.input.empty() ? o.particles : o.input, files, size.x(), size.y(),
             o.turntable > 1 ? fmt::format(", {} views", o.turntable) : "");
  fmt::print("  drawn            {}\n", what);
  if (views.scalar.pixels) {
    fmt::print("  colour           {}: mean {:.4g}, max {:.4g} over {} pixels (colour map 0 .. {:.3g})\n", content.scalar_name,
               views.scalar.mean / static_cast<double>(views.scalar.pixels), views.scalar.max, views.scalar.pixels,
               settings.surface_scalar.max_value);
  }
  fmt::print("  render           {:.3f} s on {}\n", views.seconds, renderer.device());
}

// A line of the run's summary: on standard output, or to the log under --json (standard output is
// then the JSON report alone).
void say(const Options& o, const std::string& line) {
  if (o.json) {
    log::info("{}", line);
  } else {
    fmt::print("{}\n", line);
  }
}

// The GL renderer with the --gpu-path it resolves to, named in one line.
std::unique_ptr<preview::ImageRenderer> make_gpu_renderer(const Options& o, gpu::Context& context, bool timings,
                                                          PreviewReport& report) {
  const preview::GpuPath requested = preview::parse_gpu_path(o.gpu_path).value();  // CLI::IsMember checked it
  const preview::GpuPathChoice choice = preview::choose_gpu_path(context, requested);
  auto renderer = std::make_unique<preview::Renderer>(context, timings);
  renderer->set_gpu_path(choice.path);
  say(o, "gpu path: " + choice.describe());
  report.gpu_path = choice.describe();
  return renderer;
}

// The renderer the backend rule picks (gpu/backend.h); `context` is made only where it asks the
// device (auto) or draws there (gpu), so --backend cpu runs without EGL.
std::unique_ptr<preview::ImageRenderer> make_renderer(const Options& o, const GlobalOptions& global,
                                                      std::unique_ptr<gpu::Context>& context,
                                                      PreviewReport& report) {
  const gpu::Backend requested = gpu::parse_backend(o.backend).value();  // CLI::IsMember checked it
  if (requested != gpu::Backend::Cpu) context = std::make_unique<gpu::Context>(context_options(global));
  const gpu::Backend chosen = gpu::resolve_backend(requested, context.get());
  const std::string line =
      gpu::backend_line(requested, chosen, gpu::describe(context.get()), true, "renderer");
  say(o, line);
  report.requested_backend = o.backend;
  report.backend = gpu::backend_name(chosen);
  const bool timings = o.timings || o.json;  // --json reports the per-pass times
  if (chosen == gpu::Backend::Gpu) return make_gpu_renderer(o, *context, timings, report);
  context.reset();  // the CPU draws and builds the field: the context is not needed any more
  return std::make_unique<preview::CpuRenderer>(timings);
}

// --json: the run's figures into the report, printed as one JSON object.
void print_json(const Options& o, const Eigen::Vector2i& size, const Content& content, const Views& views,
                const preview::RenderSettings& settings, preview::ImageRenderer& renderer, PreviewReport& r) {
  r.field_input = o.input;
  r.particles_input = o.particles;
  for (int k = 0; k < (o.contact_sheet ? 1 : o.turntable); ++k) {
    r.outputs.push_back(o.turntable > 1 && !o.contact_sheet ? numbered(o.output, k, o.turntable)
                                                            : std::filesystem::path(o.output));
  }
  r.width = size.x();
  r.height = size.y();
  r.views = o.turntable;
  r.contact_sheet = o.contact_sheet;
  r.device = renderer.device();
  r.field = content.field;
  r.voxel_size = content.voxel_size;
  if (const preview::Particles& p = content.loaded.particles; !p.centers.empty()) {
    r.particles = p.centers.size();
    r.particle_radius = p.radii[0];
    r.radius_source = content.loaded.radius_source;
  }
  r.colour_by = o.color_by;
  r.colour_pixels = views.scalar.pixels;
  r.colour_mean = views.scalar.mean;  // summed over pixels by render_views
  r.colour_max = views.scalar.max;
  r.colour_map_max = settings.surface_scalar.max_value;
  r.render_seconds = views.seconds;
  r.passes = renderer.pass_times();
  fmt::print("{}\n", preview_report_json(r).dump(2));
}

int run_preview(const Options& o, const GlobalOptions& global) {
  check_options(o);
  const Eigen::Vector2i size = parse_size(o.size);
  std::unique_ptr<gpu::Context> context;
  PreviewReport report;
  const std::unique_ptr<preview::ImageRenderer> renderer = make_renderer(o, global, context, report);
  renderer->check_image_size(size.x(), size.y());
  Content content;
  load_field(o, context.get(), *renderer, content);
  load_particles(o, *renderer, content);
  preview::RenderSettings settings;
  set_surface_colouring(o, content, settings);
  set_lighting(o, size, settings);
  const preview::Camera camera = make_camera(o, renderer->content_box(), static_cast<double>(size.x()) / size.y());
  const Views views = render_views(o, *renderer, settings, camera, content.inputs);
  if (o.json) {
    print_json(o, size, content, views, settings, *renderer, report);
    return 0;
  }
  print_summary(o, size, content, views, settings, *renderer);
  if (o.timings) fmt::print("{}", renderer->timing_report());
  return 0;
}

}  // namespace

Runner add_preview_command(CLI::App& app, const GlobalOptions& global) {
  return add_command<Options>(app, global, "preview",
                              "Off-screen preview: ray-cast SDF (of a mesh or a .vdb or .nvdb level set) with particles as "
                              "spheres, to PNG, on the GL device or the CPU",
                              run_preview, add_input_options, add_camera_options, add_colour_options, add_sdf_options,
                              add_lighting_options);
}

}  // namespace ts::app
