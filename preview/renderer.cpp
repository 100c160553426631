#include "preview/renderer.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/error.h"
#include "gpu/gl.h"
#include "gpu/graphics.h"
#include "gpu/params.h"
#include "preview/colors.h"
#include "preview/frame.h"
#include "shaders/preview/bindings.h"

namespace ts::preview {

namespace {

// A render target of the preview: one mip level, sampled with `filter`, clamped at the edges.
gpu::Texture make_target(GLenum format, int width, int height, GLenum filter, const char* what) {
  gpu::Texture texture = gpu::Texture::create_2d(format, width, height, what);
  texture.set_sampling(filter);
  return texture;
}

using gpu::params::CameraParams;
using gpu::params::ParticleParams;
using gpu::params::RaycastParams;

// xyz of a parameter vector (w 0), rounded to float.
gpu::params::vec4 xyz(const Eigen::Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()), 0.0f};
}
gpu::params::vec4 xyz(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z(), 0.0f}; }
gpu::params::mat4 matrix(const Eigen::Matrix4d& m) {
  const Eigen::Matrix4f f = m.cast<float>();  // Eigen is column-major, as GLSL's mat4
  gpu::params::mat4 out;
  for (int c = 0; c < 4; ++c) out.column[c] = {f(0, c), f(1, c), f(2, c), f(3, c)};
  return out;
}

CameraParams camera_params(const CameraState& c) {
  CameraParams p;
  p.view_projection = matrix(c.view_projection);
  p.inverse_view_projection = matrix(c.inverse);
  p.eye = xyz(c.eye);
  p.forward = xyz(c.forward);
  p.right = xyz(c.right);
  p.up = xyz(c.up);
  p.lens = {c.ortho ? 1 : 0, 0, 0, 0};
  p.viewport = {static_cast<float>(c.width), static_cast<float>(c.height), 0.0f, 0.0f};
  return p;
}

// Rows bottom-up (GL) -> top-down (images).
template <typename T>
std::vector<T> flip_rows(const std::vector<T>& in, int width, int height, int per_pixel) {
  std::vector<T> out(in.size());
  const std::size_t row = static_cast<std::size_t>(width) * per_pixel;
  for (int y = 0; y < height; ++y) {
    std::copy_n(in.begin() + static_cast<std::ptrdiff_t>(row * (height - 1 - y)), row,
                out.begin() + static_cast<std::ptrdiff_t>(row * y));
  }
  return out;
}

}  // namespace

struct Renderer::Impl {
  explicit Impl(gpu::Context& c, bool timings)
      : context(c),
        queue(timings, c.debug()),
        particles_program(
            gpu::Program::graphics(library, "preview/particles.vert", "", "preview/particles.frag")),
        raycast_program(gpu::Program::graphics(library, "preview/raycast.vert", "", "preview/raycast.frag")),
        shade_program(gpu::Program::graphics(library, "preview/shade.vert", "", "preview/shade.frag")),
        vao(gpu::VertexArray::create()) {
    if (c.limits().max_vertex_shader_storage_blocks < 2) {
      throw GpuError("the preview needs shader storage buffers in vertex shaders, which this GPU lacks");
    }
  }

  void ensure_targets(int w, int h);
  void ensure_shadow_map(int size);
  void upload_particles(const Eigen::Vector3d& new_origin);
  void bind_camera(gpu::ParamBlock<CameraParams>& block, const CameraState& camera);
  void bind_volume();
  void draw_particles(gpu::ParamBlock<ParticleParams>& params);
  void draw_volume(gpu::ParamBlock<RaycastParams>& params);
  void shadow_pass(const Frame& f);
  void particle_pass(const RenderSettings& s, const Frame& f);
  void raycast_pass(const RenderSettings& s, const Frame& f);
  void colour_surface(const RenderSettings& s, const CameraState& camera, RenderResult& result);
  void lighting_pass(const RenderSettings& s, const Frame& f);
  void bind_lighting_params(const RenderSettings& s, const Frame& f);
  void read_back(const RenderSettings& s, RenderResult& result) const;
  void compute_passes(const RenderSettings& s, const Frame& f);
  void check(const char* what) const {
    if (context.debug()) gpu::check_gl(what);
  }

  gpu::Context& context;
  gpu::ShaderLibrary library;
  gpu::Queue queue;
  gpu::Program particles_program, raycast_program, shade_program;
  // The passes' parameters (shaders/common/params.h). The shadow pass has blocks of its own, so no
  // block is rewritten between the draws of a frame (which would make llvmpipe finish them first).
  gpu::ParamBlock<CameraParams> camera_block, light_camera_block;
  gpu::ParamBlock<ParticleParams> particle_block, particle_shadow_block;
  gpu::ParamBlock<RaycastParams> raycast_block, raycast_shadow_block;
  gpu::ParamBlock<gpu::params::VolumeParams> volume_block;
  gpu::ParamBlock<gpu::params::ShadeParams> shade_block;
  std::vector<std::string> volume_defines;  // what raycast_program and shade_program were compiled with
  gpu::VertexArray vao;  // none of the passes reads vertex attributes, but GL draws need one bound

  // The SDF: the sparse field, its metadata, and the box of its surface.
  sdf::SparseField field;
  sdf::GridSpec volume_spec;
  double volume_band = 0.0;
  bool has_volume = false;
  Aabb surface_box, volume_box;

  // Particles: kept on the CPU, uploaded relative to the origin in use.
  Particles particles;
  Aabb particle_box;
  bool particles_dirty = false;
  gpu::Buffer spheres, colors;
  std::size_t particle_count = 0;
  bool per_particle_color = false;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();

  // The compute shadow map and G-buffer (set_gpu_path), compiled on first use.
  GpuPath path = GpuPath::Raster;
  std::unique_ptr<ComputePasses> compute;
  gpu::ParamBlock<gpu::params::PreviewComputeParams> compute_block, compute_shadow_block;

  // Targets.
  int width = 0, height = 0, shadow_size = 0;
  gpu::Texture albedo, normal, depth, particle_depth, final_color, shadow_depth;
  gpu::Framebuffer gbuffer, final_target, shadow_target;
};

void Renderer::Impl::ensure_targets(int w, int h) {
  if (w == width && h == height) return;
  albedo = make_target(GL_RGBA8, w, h, GL_NEAREST, "preview albedo buffer");
  normal = make_target(GL_RGBA16F, w, h, GL_NEAREST, "preview normal buffer");
  depth = make_target(GL_DEPTH_COMPONENT32F, w, h, GL_NEAREST, "preview depth buffer");
  particle_depth = make_target(GL_DEPTH_COMPONENT32F, w, h, GL_NEAREST, "preview particle depth");
  final_color = make_target(GL_RGBA8, w, h, GL_NEAREST, "preview image");
  gbuffer = gpu::Framebuffer("preview G-buffer");
  gbuffer.attach_color(0, albedo);
  gbuffer.attach_color(1, normal);
  gbuffer.attach_depth(depth);
  gbuffer.set_draw_buffers(2);
  gbuffer.check_complete();
  final_target = gpu::Framebuffer("preview image");
  final_target.attach_color(0, final_color);
  final_target.check_complete();
  width = w;
  height = h;
}

void Renderer::Impl::ensure_shadow_map(int size) {
  if (size == shadow_size) return;
  shadow_depth = make_target(GL_DEPTH_COMPONENT32F, size, size, GL_LINEAR, "preview shadow map");
  shadow_depth.set_depth_compare(GL_LEQUAL);
  shadow_target = gpu::Framebuffer("preview shadow map");
  shadow_target.attach_depth(shadow_depth);
  shadow_target.set_draw_buffers(0);
  shadow_target.check_complete();
  shadow_size = size;
}

void Renderer::Impl::upload_particles(const Eigen::Vector3d& new_origin) {
  if (!particles_dirty && new_origin == origin) return;
  origin = new_origin;
  particles_dirty = false;
  const std::size_t n = particles.centers.size();
  std::vector<Eigen::Vector4f> packed(n);
  const bool one_radius = particles.radii.size() == 1;
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    const Eigen::Vector3f c = (particles.centers[i] - origin).cast<float>();
    packed[i] = Eigen::Vector4f(c.x(), c.y(), c.z(), particles.radii[one_radius ? 0 : i]);
  });
  spheres = gpu::Buffer(n * sizeof(Eigen::Vector4f), packed.data());
  per_particle_color = !particles.colors.empty();
  colors = gpu::Buffer(per_particle_color ? n * sizeof(std::uint32_t) : 4,
                       per_particle_color ? particles.colors.data() : nullptr);
  particle_count = n;
}

void Renderer::Impl::bind_camera(gpu::ParamBlock<CameraParams>& block, const CameraState& camera) {
  block.values = camera_params(camera);
  block.bind(TS_PREVIEW_CAMERA);
}

void Renderer::Impl::bind_volume() {
  field.bind({TS_PREVIEW_SPARSE_FIELD,
              {TS_PREVIEW_FIELD_CHUNK_1, TS_PREVIEW_FIELD_CHUNK_2, TS_PREVIEW_FIELD_CHUNK_3, TS_PREVIEW_FIELD_CHUNK_4,
               TS_PREVIEW_FIELD_CHUNK_5, TS_PREVIEW_FIELD_CHUNK_6, TS_PREVIEW_FIELD_CHUNK_7},
              TS_PREVIEW_FIELD_PARAMS, TS_PREVIEW_FIELD_ROOTS});
  volume_block.values.origin_voxel = xyz(Eigen::Vector3d(volume_spec.origin - origin));
  volume_block.values.origin_voxel.w = static_cast<float>(volume_spec.voxel_size);
  volume_block.values.dims_band = {static_cast<float>(volume_spec.dims.x()), static_cast<float>(volume_spec.dims.y()),
                                   static_cast<float>(volume_spec.dims.z()), static_cast<float>(volume_band)};
  volume_block.bind(TS_PREVIEW_VOLUME);
}

void Renderer::Impl::draw_particles(gpu::ParamBlock<ParticleParams>& params) {
  if (particle_count == 0) return;
  params.bind(TS_PREVIEW_PARAMS);
  spheres.bind(TS_PREVIEW_SPHERES);
  colors.bind(TS_PREVIEW_COLORS);
  gpu::StateScope state;
  state.no_cull();
  gpu::draw_arrays(queue, particles_program, GL_TRIANGLES, 0, 6 * particle_count);
}

void Renderer::Impl::draw_volume(gpu::ParamBlock<RaycastParams>& params) {
  if (!has_volume) return;
  bind_volume();
  // Steps of the refinement near each crossing the HDDA finds (a few voxels long), grazing rays included.
  params.values.flags.z = 512;
  params.values.steps.x = 0.02f;
  params.bind(TS_PREVIEW_PARAMS);
  // Front faces culled: one fragment per covered pixel, on the far face, also with the eye inside.
  gpu::StateScope state;
  state.cull(GL_FRONT);
  gpu::draw_arrays(queue, raycast_program, GL_TRIANGLES, 0, 36);
}

// 1. The key light's shadow map: particles and the SDF, depth only.
void Renderer::Impl::shadow_pass(const Frame& f) {
  ensure_shadow_map(f.shadow_size);
  queue.timed("preview/shadow map", [&] {
    gpu::StateScope pass;
    pass.framebuffer(shadow_target).viewport(f.shadow_size, f.shadow_size);
    shadow_target.clear_depth(1.0f);
    bind_camera(light_camera_block, f.light_camera);
    particle_shadow_block.values.flags.x = 0;
    draw_particles(particle_shadow_block);
    raycast_shadow_block.values.flags.x = 0;  // no particle depth
    raycast_shadow_block.values.flags.y = 1;  // depth only
    draw_volume(raycast_shadow_block);
  });
}

// 2a. G-buffer: the particles, as sphere impostors with their true depth and normal.
void Renderer::Impl::particle_pass(const RenderSettings& s, const Frame& f) {
  queue.timed("preview/particles", [&] {
    gpu::StateScope pass;
    pass.framebuffer(gbuffer).viewport(s.width, s.height);
    gbuffer.clear_color(0, {0.0f, 0.0f, 0.0f, 0.0f});
    gbuffer.clear_color(1, {0.0f, 0.0f, 0.0f, 0.0f});
    gbuffer.clear_depth(1.0f);
    bind_camera(camera_block, f.camera);
    particle_block.values.flags.x = per_particle_color ? 1 : 0;
    particle_block.values.color = xyz(s.particle_color);
    draw_particles(particle_block);
  });
}

// 2b. G-buffer: the SDF, each ray marched up to the particle already drawn at its pixel.
void Renderer::Impl::raycast_pass(const RenderSettings& s, const Frame& f) {
  queue.timed("preview/ray cast", [&] {
    gpu::StateScope pass;
    pass.framebuffer(gbuffer).viewport(s.width, s.height);
    const bool limit = particle_count > 0;
    // The ray cast reads the particle depth while the depth test writes the G-buffer's: a copy.
    if (limit) depth.copy_to(particle_depth);
    particle_depth.bind_unit(TS_PREVIEW_UNIT_PARTICLE_DEPTH);
    raycast_block.values.flags.x = limit ? 1 : 0;
    raycast_block.values.flags.y = 0;
    raycast_block.values.surface_color = xyz(s.surface_color);
    bind_camera(camera_block, f.camera);
    draw_volume(raycast_block);
  });
}

// 1 and 2 by compute kernels (preview/compute_passes.h): the shadow map from the light, depth only,
// then the G-buffer; the lighting pass reads them as it reads the draws'.
void Renderer::Impl::compute_passes(const RenderSettings& s, const Frame& f) {
  if (!compute) compute = std::make_unique<ComputePasses>(library, volume_defines);
  if (particle_count > 0) {
    spheres.bind(TS_PREVIEW_SPHERES);
    colors.bind(TS_PREVIEW_COLORS);
  }
  if (has_volume) bind_volume();
  ComputeScene scene{particle_count, per_particle_color, s.particle_color, s.surface_color, has_volume};
  if (s.shadows) {
    ensure_shadow_map(f.shadow_size);
    queue.timed("preview/shadow map (compute)", [&] {
      bind_camera(light_camera_block, f.light_camera);
      compute->draw(queue, scene, {&shadow_depth, nullptr, nullptr}, compute_shadow_block);
    });
  }
  queue.timed("preview/G-buffer (compute)", [&] {
    bind_camera(camera_block, f.camera);
    compute->draw(queue, scene, {&depth, &albedo, &normal}, compute_block);
  });
}

// 4. Lighting: one full-screen triangle over the G-buffer.
void Renderer::Impl::lighting_pass(const RenderSettings& s, const Frame& f) {
  queue.timed("preview/shade", [&] {
    gpu::StateScope pass;
    pass.no_depth_test().framebuffer(final_target).viewport(s.width, s.height);
    albedo.bind_unit(TS_PREVIEW_UNIT_ALBEDO);
    normal.bind_unit(TS_PREVIEW_UNIT_NORMAL);
    depth.bind_unit(TS_PREVIEW_UNIT_DEPTH);
    if (s.shadows) {
      shadow_depth.bind_unit(TS_PREVIEW_UNIT_SHADOW);
    } else {
      gpu::Texture::unbind_unit(TS_PREVIEW_UNIT_SHADOW);
    }
    if (has_volume) bind_volume();
    bind_lighting_params(s, f);
    gpu::draw_arrays(queue, shade_program, GL_TRIANGLES, 0, 3);
  });
}

void Renderer::Impl::bind_lighting_params(const RenderSettings& s, const Frame& f) {
  bind_camera(camera_block, f.camera);
  gpu::params::ShadeParams& p = shade_block.values;
  if (s.shadows) {
    p.light_view_projection = matrix(f.light_camera.view_projection);
    p.shadow = {static_cast<float>(f.shadow_texel), static_cast<float>(f.shadow_bias), 1.0f / shadow_size,
                1.0f / shadow_size};
  }
  p.flags = {s.shadows ? 1 : 0, has_volume ? 1 : 0, s.ground ? 1 : 0, s.alpha ? 1 : 0};
  p.light_dir = xyz(f.light);
  p.world_up = xyz(f.up);
  p.ground = xyz(f.ground_center);
  p.ground.w = static_cast<float>(f.ground_level);
  p.ground_color = xyz(kGroundColor);
  p.ground_color.w = static_cast<float>(f.ground_fade);
  p.background_top = xyz(kBackgroundTop);
  p.background_bottom = xyz(kBackgroundBottom);
  shade_block.bind(TS_PREVIEW_PARAMS);
}

// The image, and with keep_buffers each pixel's layer and normal, top row first.
void Renderer::Impl::read_back(const RenderSettings& s, RenderResult& result) const {
  const std::size_t pixels = static_cast<std::size_t>(s.width) * s.height;
  std::vector<std::uint8_t> rgba(4 * pixels);
  final_color.read(rgba.data(), rgba.size(), GL_RGBA, GL_UNSIGNED_BYTE);
  result.image.width = s.width;
  result.image.height = s.height;
  result.image.alpha = s.alpha;
  result.image.rgba = flip_rows(rgba, s.width, s.height, 4);
  if (s.keep_buffers) {
    std::vector<float> nl(4 * pixels);
    normal.read(nl.data(), nl.size() * sizeof(float), GL_RGBA, GL_FLOAT);
    nl = flip_rows(nl, s.width, s.height, 4);
    result.layers.resize(pixels);
    result.normals.resize(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
      result.layers[i] = static_cast<Layer>(static_cast<int>(nl[4 * i + 3] + 0.5f));
      result.normals[i] = Eigen::Vector3f(nl[4 * i], nl[4 * i + 1], nl[4 * i + 2]);
    }
  }
  check("preview read back");
}

void Renderer::Impl::colour_surface(const RenderSettings& s, const CameraState& camera, RenderResult& result) {
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  std::vector<float> depths(pixels), normals(4 * pixels);
  std::vector<std::uint8_t> colours(4 * pixels);
  depth.read(depths.data(), pixels * 4, GL_DEPTH_COMPONENT, GL_FLOAT);
  normal.read(normals.data(), pixels * 16, GL_RGBA, GL_FLOAT);
  albedo.read(colours.data(), pixels * 4, GL_RGBA, GL_UNSIGNED_BYTE);
  std::vector<double> values(pixels, std::numeric_limits<double>::quiet_NaN());
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      if (static_cast<int>(normals[4 * i + 3] + 0.5f) != TS_PREVIEW_LAYER_SURFACE) continue;
      const Eigen::Vector4d ndc(2.0 * (x + 0.5) / width - 1.0, 2.0 * (y + 0.5) / height - 1.0, 2.0 * depths[i] - 1.0,
                                1.0);
      const Eigen::Vector4d w = camera.inverse * ndc;
      const Eigen::Vector3d p = w.head<3>() / w.w() + origin;
      values[i] = s.surface_scalar.value(p);
      const Eigen::Vector3f c = viridis(values[i] / s.surface_scalar.max_value);
      for (int k = 0; k < 3; ++k) colours[4 * i + k] = static_cast<std::uint8_t>(std::lround(255.0f * c[k]));
    }
  });
  albedo.upload(colours.data(), GL_RGBA, GL_UNSIGNED_BYTE);
  result.scalar = summarize_scalar(values);
}

Renderer::Renderer(gpu::Context& context, bool timings) : impl_(std::make_unique<Impl>(context, timings)) {}
Renderer::~Renderer() = default;

void Renderer::set_volume(SdfVolume volume, std::size_t field_block_bytes) {
  Impl& m = *impl_;
  const Eigen::Vector3i& d = volume.spec.dims;
  if (volume.empty() || d.minCoeff() < 2) {
    throw InputError("the SDF to preview is empty or smaller than 2 voxels along an axis");
  }
  m.field = sdf::SparseField(std::move(volume.grid), volume.spec, volume.band, field_block_bytes);
  m.check("preview SDF upload");
  // The programs that read the field are compiled for its chunking (one storage block, or several).
  if (m.field.shader_defines() != m.volume_defines) {
    m.volume_defines = m.field.shader_defines();
    m.raycast_program =
        gpu::Program::graphics(m.library, "preview/raycast.vert", "", "preview/raycast.frag", m.volume_defines);
    m.shade_program = gpu::Program::graphics(m.library, "preview/shade.vert", "", "preview/shade.frag", m.volume_defines);
  }
  if (m.compute) m.compute->set_volume_defines(m.library, m.volume_defines);
  m.volume_spec = volume.spec;
  m.volume_band = volume.band;
  m.volume_box = volume.world_box();
  m.has_volume = true;
  m.surface_box = volume.surface;
}

int Renderer::field_chunks() const { return impl_->has_volume ? impl_->field.chunk_count() : 0; }

void Renderer::set_particles(const Particles& particles) {
  Impl& m = *impl_;
  const std::size_t n = particles.centers.size();
  const long long max_bytes = m.context.limits().max_ssbo_bytes;
  if (max_bytes > 0 && static_cast<long long>(n * sizeof(Eigen::Vector4f)) > max_bytes) {
    throw InputError(fmt::format("{} particles exceed this GPU's largest storage buffer ({} particles)", n,
                                 max_bytes / static_cast<long long>(sizeof(Eigen::Vector4f))));
  }
  const Aabb box = particle_box(particles);
  m.particles = particles;
  m.particle_box = box;
  m.particles_dirty = true;
}

Aabb Renderer::content_box() const {
  return preview::content_box(impl_->has_volume ? std::optional<Aabb>(impl_->surface_box) : std::nullopt,
                              impl_->particle_box);
}

Eigen::Vector2i Renderer::max_image_size() const {
  const gpu::DeviceLimits& l = impl_->context.limits();
  return {std::min({l.max_viewport_dims[0], l.max_texture_size, l.max_framebuffer_size[0]}),
          std::min({l.max_viewport_dims[1], l.max_texture_size, l.max_framebuffer_size[1]})};
}

void Renderer::check_image_size(int width, int height) const {
  const Eigen::Vector2i max_size = max_image_size();
  if (width < 1 || height < 1) {
    throw InputError(fmt::format("image size {} x {}: both sides must be at least 1 pixel", width, height));
  }
  if (width > max_size.x() || height > max_size.y()) {
    throw InputError(fmt::format("image size {} x {} exceeds this GPU's largest render target, {} x {} ({})", width,
                                 height, max_size.x(), max_size.y(), impl_->context.renderer()));
  }
}

RenderResult Renderer::render(const RenderSettings& s) {
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  check_image_size(s.width, s.height);
  const Aabb content = content_box();
  const Frame frame = plan_frame(s, content, m.has_volume ? std::optional<Aabb>(m.volume_box) : std::nullopt,
                                 max_image_size().maxCoeff());
  m.upload_particles(frame.origin);
  m.ensure_targets(s.width, s.height);

  gpu::StateScope state;
  state.vertex_array(m.vao).depth_test(GL_LESS).no_cull().no_blend();
  if (m.path == GpuPath::Compute) {
    m.compute_passes(s, frame);
  } else {
    if (s.shadows) m.shadow_pass(frame);
    m.particle_pass(s, frame);
    m.raycast_pass(s, frame);
  }
  RenderResult result;
  // 3. CPU colouring of the surface.
  if (s.surface_scalar.value && m.has_volume) m.colour_surface(s, frame.camera, result);
  m.lighting_pass(s, frame);
  m.read_back(s, result);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void Renderer::set_gpu_path(GpuPath path) {
  if (path == GpuPath::Auto) {
    throw std::invalid_argument("Renderer::set_gpu_path: resolve auto first (preview::choose_gpu_path)");
  }
  impl_->path = path;
}

GpuPath Renderer::gpu_path() const { return impl_->path; }

std::vector<PassTime> Renderer::pass_times() {
  std::vector<PassTime> passes;
  for (const gpu::KernelTiming& t : impl_->queue.timings()) passes.push_back({t.name, t.calls, t.milliseconds});
  return passes;
}

std::string Renderer::timing_report() { return impl_->queue.timing_report(); }

std::string Renderer::device() const { return impl_->context.summary(); }

}  // namespace ts::preview
