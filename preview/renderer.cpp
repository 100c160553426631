#include "preview/renderer.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "gpu/gl.h"
#include "preview/colors.h"
#include "shaders/preview/bindings.h"

namespace ts::preview {

namespace {

constexpr std::size_t kMaxR32Bytes = std::size_t{256} << 20;  // larger volumes are stored as R16F

// Owns one GL texture or framebuffer name.
class GlName {
 public:
  using Deleter = void (*)(GLsizei, const GLuint*);
  explicit GlName(Deleter deleter) : deleter_(deleter) {}
  ~GlName() { reset(); }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  void reset(GLuint id = 0) {
    if (id_) deleter_(1, &id_);
    id_ = id;
  }
  GLuint get() const { return id_; }

 private:
  Deleter deleter_;
  GLuint id_ = 0;
};

void delete_textures(GLsizei n, const GLuint* ids) { glDeleteTextures(n, ids); }
void delete_framebuffers(GLsizei n, const GLuint* ids) { glDeleteFramebuffers(n, ids); }

GLuint make_texture_2d(GLenum format, int width, int height, GLenum filter, const char* what) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  glTextureStorage2D(id, 1, format, width, height);
  if (glGetError() == GL_OUT_OF_MEMORY) {
    glDeleteTextures(1, &id);
    throw GpuError(fmt::format("out of GPU memory for the preview's {} ({} x {})", what, width, height));
  }
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, filter);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, filter);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return id;
}

void check_framebuffer(GLuint fbo, const char* what) {
  const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw GpuError(fmt::format("the preview's {} framebuffer is incomplete (status 0x{:x})", what, status));
  }
}

// The camera as every pass sees it: relative to the scene origin, in float.
struct CameraState {
  Eigen::Matrix4d view_projection, inverse;
  Eigen::Vector3d eye, forward, right, up;  // eye relative to the origin
  bool ortho = false;
  int width = 0, height = 0;
};

CameraState camera_state(const Camera& camera, int width, int height, const Eigen::Vector3d& origin, double radius) {
  Camera local = camera;
  local.eye -= origin;
  local.target -= origin;
  const ViewMatrices m =
      view_matrices(local, static_cast<double>(width) / height, Eigen::Vector3d::Zero(), radius);
  CameraState s;
  s.view_projection = m.projection * m.view;
  s.inverse = s.view_projection.inverse();
  s.eye = local.eye;
  s.forward = local.forward();
  s.right = local.right();
  s.up = local.image_up();
  s.ortho = camera.ortho;
  s.width = width;
  s.height = height;
  return s;
}

void set_vec3(const gpu::Program& p, const char* name, const Eigen::Vector3d& v) {
  p.set(name, static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
}
void set_vec3(const gpu::Program& p, const char* name, const Eigen::Vector3f& v) { p.set(name, v.x(), v.y(), v.z()); }
void set_matrix(const gpu::Program& p, const char* name, const Eigen::Matrix4d& m) {
  const Eigen::Matrix4f f = m.cast<float>();  // Eigen is column-major, as GL expects
  p.set_matrix4(name, f.data());
}

void set_camera(const gpu::Program& p, const CameraState& c) {
  set_matrix(p, "view_projection", c.view_projection);
  set_matrix(p, "inverse_view_projection", c.inverse);
  set_vec3(p, "eye", c.eye);
  set_vec3(p, "view_forward", c.forward);
  set_vec3(p, "view_right", c.right);
  set_vec3(p, "view_up", c.up);
  p.set("orthographic", c.ortho ? 1 : 0);
  p.set("viewport", static_cast<float>(c.width), static_cast<float>(c.height));
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

Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& v) {
  const Eigen::Vector3d a = std::abs(v.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return v.cross(a).normalized();
}

}  // namespace

Eigen::Vector3d default_light(const Camera& camera, const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  Eigen::Vector3d back = -camera.forward();
  back -= back.dot(u) * u;
  if (back.norm() < 1e-6) {  // looking straight down or up: the image's down is "towards the camera"
    back = -camera.image_up();
    back -= back.dot(u) * u;
  }
  if (back.norm() < 1e-6) back = any_perpendicular(u);
  back.normalize();
  const Eigen::Vector3d right = u.cross(back).normalized();
  return (0.85 * u + 0.5 * back - 0.45 * right).normalized();
}

struct Renderer::Impl {
  explicit Impl(gpu::Context& c, bool timings)
      : context(c),
        queue(timings, c.debug()),
        particles_program(gpu::Program::graphics(library, "preview/particles.vert", "", "preview/particles.frag")),
        raycast_program(gpu::Program::graphics(library, "preview/raycast.vert", "", "preview/raycast.frag")),
        shade_program(gpu::Program::graphics(library, "preview/shade.vert", "", "preview/shade.frag")) {
    glCreateVertexArrays(1, &vao);
    GLint blocks = 0;
    glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &blocks);
    if (blocks < 2) throw GpuError("the preview needs shader storage buffers in vertex shaders, which this GPU lacks");
    // Every sampler gets its own unit once: two samplers of different types left on unit 0 would
    // make draws fail (GL_INVALID_OPERATION) whether or not the shader reads them.
    raycast_program.set("volume", TS_PREVIEW_UNIT_VOLUME);
    raycast_program.set("particle_depth", TS_PREVIEW_UNIT_PARTICLE_DEPTH);
    shade_program.set("volume", TS_PREVIEW_UNIT_VOLUME);
    shade_program.set("albedo_texture", TS_PREVIEW_UNIT_ALBEDO);
    shade_program.set("normal_texture", TS_PREVIEW_UNIT_NORMAL);
    shade_program.set("depth_texture", TS_PREVIEW_UNIT_DEPTH);
    shade_program.set("shadow_map", TS_PREVIEW_UNIT_SHADOW);
  }
  ~Impl() {
    if (vao) glDeleteVertexArrays(1, &vao);
  }

  void ensure_targets(int w, int h);
  void ensure_shadow_map(int size);
  void upload_particles(const Eigen::Vector3d& new_origin);
  void bind_volume(const gpu::Program& p) const;
  void draw_particles(const gpu::Program& p) const;
  void draw_volume(const gpu::Program& p) const;
  void colour_surface(const RenderSettings& s, const CameraState& camera, RenderResult& result);
  void check(const char* what) const {
    if (context.debug()) gpu::check_gl(what);
  }

  gpu::Context& context;
  gpu::ShaderLibrary library;
  gpu::Queue queue;
  gpu::Program particles_program, raycast_program, shade_program;
  GLuint vao = 0;

  // The SDF: texture, metadata, and the box of its surface.
  GlName volume_texture{delete_textures};
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

  // Targets.
  int width = 0, height = 0, shadow_size = 0;
  GlName gbuffer{delete_framebuffers}, final_target{delete_framebuffers}, shadow_target{delete_framebuffers};
  GlName albedo{delete_textures}, normal{delete_textures}, depth{delete_textures}, particle_depth{delete_textures},
      final_color{delete_textures}, shadow_depth{delete_textures};
};

void Renderer::Impl::ensure_targets(int w, int h) {
  if (w == width && h == height) return;
  albedo.reset(make_texture_2d(GL_RGBA8, w, h, GL_NEAREST, "albedo buffer"));
  normal.reset(make_texture_2d(GL_RGBA16F, w, h, GL_NEAREST, "normal buffer"));
  depth.reset(make_texture_2d(GL_DEPTH_COMPONENT32F, w, h, GL_NEAREST, "depth buffer"));
  particle_depth.reset(make_texture_2d(GL_DEPTH_COMPONENT32F, w, h, GL_NEAREST, "particle depth"));
  final_color.reset(make_texture_2d(GL_RGBA8, w, h, GL_NEAREST, "image"));
  GLuint fbo = 0;
  glCreateFramebuffers(1, &fbo);
  gbuffer.reset(fbo);
  glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, albedo.get(), 0);
  glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT1, normal.get(), 0);
  glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth.get(), 0);
  const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glNamedFramebufferDrawBuffers(fbo, 2, buffers);
  check_framebuffer(fbo, "G-buffer");
  glCreateFramebuffers(1, &fbo);
  final_target.reset(fbo);
  glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, final_color.get(), 0);
  check_framebuffer(fbo, "image");
  width = w;
  height = h;
}

void Renderer::Impl::ensure_shadow_map(int size) {
  if (size == shadow_size) return;
  shadow_depth.reset(make_texture_2d(GL_DEPTH_COMPONENT32F, size, size, GL_LINEAR, "shadow map"));
  glTextureParameteri(shadow_depth.get(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(shadow_depth.get(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  GLuint fbo = 0;
  glCreateFramebuffers(1, &fbo);
  shadow_target.reset(fbo);
  glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, shadow_depth.get(), 0);
  glNamedFramebufferDrawBuffer(fbo, GL_NONE);
  check_framebuffer(fbo, "shadow map");
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

void Renderer::Impl::bind_volume(const gpu::Program& p) const {
  glBindTextureUnit(TS_PREVIEW_UNIT_VOLUME, volume_texture.get());
  set_vec3(p, "volume_origin", Eigen::Vector3d(volume_spec.origin - origin));
  p.set("voxel_size", static_cast<float>(volume_spec.voxel_size));
  p.set("volume_dims", static_cast<float>(volume_spec.dims.x()), static_cast<float>(volume_spec.dims.y()),
        static_cast<float>(volume_spec.dims.z()));
  p.set("band", static_cast<float>(volume_band));
}

void Renderer::Impl::draw_particles(const gpu::Program& p) const {
  if (particle_count == 0) return;
  p.use();
  spheres.bind(TS_PREVIEW_SPHERES);
  colors.bind(TS_PREVIEW_COLORS);
  glDisable(GL_CULL_FACE);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(6 * particle_count));
  check("preview particles");
}

void Renderer::Impl::draw_volume(const gpu::Program& p) const {
  if (!has_volume) return;
  p.use();
  bind_volume(p);
  const Eigen::Vector3i& d = volume_spec.dims;
  // Enough steps to cross the box at the band's stride, and many more for grazing rays.
  p.set("max_steps", static_cast<int>(4 * (d.x() + d.y() + d.z()) / std::max(1.0, volume_band)) + 512);
  p.set("min_step", 0.02f);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_FRONT);
  glDrawArrays(GL_TRIANGLES, 0, 36);
  glDisable(GL_CULL_FACE);
  check("preview ray cast");
}

void Renderer::Impl::colour_surface(const RenderSettings& s, const CameraState& camera, RenderResult& result) {
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  std::vector<float> depths(pixels), normals(4 * pixels);
  std::vector<std::uint8_t> colours(4 * pixels);
  glGetTextureImage(depth.get(), 0, GL_DEPTH_COMPONENT, GL_FLOAT, static_cast<GLsizei>(pixels * 4), depths.data());
  glGetTextureImage(normal.get(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(pixels * 16), normals.data());
  glGetTextureImage(albedo.get(), 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(pixels * 4), colours.data());
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
  glTextureSubImage2D(albedo.get(), 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, colours.data());
  double sum = 0.0;
  for (double v : values) {
    if (std::isnan(v)) continue;
    ++result.scalar.pixels;
    sum += v;
    result.scalar.max = std::max(result.scalar.max, v);
  }
  if (result.scalar.pixels) result.scalar.mean = sum / static_cast<double>(result.scalar.pixels);
}

Renderer::Renderer(gpu::Context& context, bool timings) : impl_(std::make_unique<Impl>(context, timings)) {}
Renderer::~Renderer() = default;

void Renderer::set_volume(const SdfVolume& volume) {
  Impl& m = *impl_;
  const Eigen::Vector3i& d = volume.spec.dims;
  if (volume.empty() || d.minCoeff() < 2 || volume.distance.size() != volume.spec.voxel_count()) {
    throw InputError("the SDF to preview is empty or smaller than 2 voxels along an axis");
  }
  const int max_side = m.context.limits().max_3d_texture_size;
  if (d.maxCoeff() > max_side) {
    throw InputError(fmt::format("the SDF grid is {} x {} x {} voxels; this GPU's 3D textures hold at most {} per side "
                                 "(use a lower --resolution or a larger --voxel)",
                                 d.x(), d.y(), d.z(), max_side));
  }
  const bool half = volume.spec.voxel_count() * sizeof(float) > kMaxR32Bytes;
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_3D, 1, &id);
  m.volume_texture.reset(id);
  glTextureStorage3D(id, 1, half ? GL_R16F : GL_R32F, d.x(), d.y(), d.z());
  if (glGetError() == GL_OUT_OF_MEMORY) {
    m.volume_texture.reset();
    m.has_volume = false;
    throw GpuError(fmt::format("out of GPU memory for the preview's {} x {} x {} SDF texture", d.x(), d.y(), d.z()));
  }
  // Upload in slabs of about 64 MiB so the driver's staging copy stays small.
  const std::size_t slice = static_cast<std::size_t>(d.x()) * d.y();
  const int slab = std::max(1, static_cast<int>((std::size_t{64} << 20) / (4 * slice)));
  for (int z = 0; z < d.z(); z += slab) {
    const int n = std::min(slab, d.z() - z);
    glTextureSubImage3D(id, 0, 0, 0, z, d.x(), d.y(), n, GL_RED, GL_FLOAT, volume.distance.data() + slice * z);
  }
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (GLenum axis : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTextureParameteri(id, axis, GL_CLAMP_TO_EDGE);
  m.check("preview SDF upload");
  m.volume_spec = volume.spec;
  m.volume_band = volume.band;
  m.volume_box = volume.world_box();
  m.has_volume = true;

  // The surface's box: voxels at or inside the zero level, grown by half a voxel.
  std::vector<Aabb> slices(static_cast<std::size_t>(d.z()));
  tbb::parallel_for(0, d.z(), [&](int k) {
    for (int j = 0; j < d.y(); ++j)
      for (int i = 0; i < d.x(); ++i)
        if (volume.distance[volume.spec.linear_index(i, j, k)] <= 0.0f) slices[k].extend(volume.spec.voxel_center(i, j, k));
  });
  Aabb box;
  for (const Aabb& s : slices) {
    if (!s.valid()) continue;
    box.extend(s.min);
    box.extend(s.max);
  }
  if (box.valid()) {
    box.min.array() -= 0.5 * volume.spec.voxel_size;
    box.max.array() += 0.5 * volume.spec.voxel_size;
  }
  m.surface_box = box.valid() ? box : m.volume_box;
}

void Renderer::set_particles(const Particles& particles) {
  Impl& m = *impl_;
  const std::size_t n = particles.centers.size();
  if (n && particles.radii.size() != 1 && particles.radii.size() != n) {
    throw InputError("particles: give one radius, or one per particle");
  }
  if (!particles.colors.empty() && particles.colors.size() != n) throw InputError("particles: one colour per particle");
  const long long max_bytes = m.context.limits().max_ssbo_bytes;
  if (max_bytes > 0 && static_cast<long long>(n * sizeof(Eigen::Vector4f)) > max_bytes) {
    throw InputError(fmt::format("{} particles exceed this GPU's largest storage buffer ({} particles)", n,
                                 max_bytes / static_cast<long long>(sizeof(Eigen::Vector4f))));
  }
  Aabb box;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = particles.radii[particles.radii.size() == 1 ? 0 : i];
    if (!particles.centers[i].allFinite() || !(r > 0.0) || !std::isfinite(r)) {
      throw InputError(fmt::format("particle {} has a non-finite position or a radius that is not positive", i));
    }
    box.extend(particles.centers[i] - Eigen::Vector3d::Constant(r));
    box.extend(particles.centers[i] + Eigen::Vector3d::Constant(r));
  }
  m.particles = particles;
  m.particle_box = box;
  m.particles_dirty = true;
}

Aabb Renderer::content_box() const {
  Aabb box;
  if (impl_->has_volume) {
    box.extend(impl_->surface_box.min);
    box.extend(impl_->surface_box.max);
  }
  if (impl_->particle_box.valid()) {
    box.extend(impl_->particle_box.min);
    box.extend(impl_->particle_box.max);
  }
  return box;
}

Eigen::Vector2i Renderer::max_image_size() const {
  GLint viewport[2] = {0, 0}, texture = 0, fb_width = 0, fb_height = 0;
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &texture);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &fb_width);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_HEIGHT, &fb_height);
  return {std::min({viewport[0], texture, fb_width}), std::min({viewport[1], texture, fb_height})};
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
  const Eigen::Vector2i max_size = max_image_size();
  validate(s.camera);
  if (!(s.up.norm() > 0.0) || !s.up.allFinite()) throw InputError("the up vector must be finite and non-zero");
  const Aabb content = content_box();
  if (!content.valid()) throw InputError("nothing to render: no SDF and no particles");
  if (s.surface_scalar.value && !(s.surface_scalar.max_value > 0.0)) {
    throw InputError("the colour map's top value must be positive");
  }

  // Everything drawn lies in this sphere; positions go to the GPU relative to its centre.
  Aabb all = content;
  if (m.has_volume) {
    all.extend(m.volume_box.min);
    all.extend(m.volume_box.max);
  }
  const Eigen::Vector3d origin = all.center();
  const double radius = std::max(0.5 * all.size().norm(), 1e-12);
  m.upload_particles(origin);
  m.ensure_targets(s.width, s.height);
  const CameraState camera = camera_state(s.camera, s.width, s.height, origin, radius);

  const Eigen::Vector3d up = s.up.normalized();
  const Eigen::Vector3d light = s.light ? s.light->normalized() : default_light(s.camera, up);
  if (!light.allFinite()) throw InputError("the light direction must be finite and non-zero");
  double lowest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d corner(i & 1 ? content.max.x() : content.min.x(), i & 2 ? content.max.y() : content.min.y(),
                                 i & 4 ? content.max.z() : content.min.z());
    lowest = std::min(lowest, up.dot(corner));
  }
  const double ground_level = s.ground_level.value_or(lowest) - up.dot(origin);

  glBindVertexArray(m.vao);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);

  // 1. The key light's shadow map: an orthographic view along the light holding the sphere.
  CameraState light_camera;
  if (s.shadows) {
    const GLint max_texture = max_size.maxCoeff();
    const int size = std::min(s.shadow_map_size > 0 ? s.shadow_map_size : std::clamp(std::max(s.width, s.height), 512, 4096),
                              static_cast<int>(max_texture));
    m.ensure_shadow_map(size);
    Camera lc;
    lc.target = origin;
    lc.eye = origin + light * (2.0 * radius);
    lc.up = any_perpendicular(light);
    lc.ortho = true;
    lc.ortho_height = 2.02 * radius;
    light_camera = camera_state(lc, size, size, origin, radius);
    m.queue.timed("preview/shadow map", [&] {
      glBindFramebuffer(GL_FRAMEBUFFER, m.shadow_target.get());
      glViewport(0, 0, size, size);
      const float one = 1.0f;
      glClearNamedFramebufferfv(m.shadow_target.get(), GL_DEPTH, 0, &one);
      set_camera(m.particles_program, light_camera);
      m.particles_program.set("per_particle_color", 0);
      m.draw_particles(m.particles_program);
      set_camera(m.raycast_program, light_camera);
      m.raycast_program.set("use_particle_depth", 0);
      m.raycast_program.set("depth_only", 1);
      m.draw_volume(m.raycast_program);
    });
  }

  // 2. G-buffer: particles, then the SDF marched up to them.
  m.queue.timed("preview/particles", [&] {
    glBindFramebuffer(GL_FRAMEBUFFER, m.gbuffer.get());
    glViewport(0, 0, s.width, s.height);
    const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
    glClearNamedFramebufferfv(m.gbuffer.get(), GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(m.gbuffer.get(), GL_COLOR, 1, zero);
    glClearNamedFramebufferfv(m.gbuffer.get(), GL_DEPTH, 0, &one);
    set_camera(m.particles_program, camera);
    m.particles_program.set("per_particle_color", m.per_particle_color ? 1 : 0);
    set_vec3(m.particles_program, "particle_color", s.particle_color);
    m.draw_particles(m.particles_program);
  });
  m.queue.timed("preview/ray cast", [&] {
    const bool limit = m.particle_count > 0;
    if (limit) {
      glCopyImageSubData(m.depth.get(), GL_TEXTURE_2D, 0, 0, 0, 0, m.particle_depth.get(), GL_TEXTURE_2D, 0, 0, 0, 0,
                         s.width, s.height, 1);
    }
    glBindTextureUnit(TS_PREVIEW_UNIT_PARTICLE_DEPTH, m.particle_depth.get());
    m.raycast_program.set("use_particle_depth", limit ? 1 : 0);
    m.raycast_program.set("depth_only", 0);
    set_vec3(m.raycast_program, "surface_color", s.surface_color);
    set_camera(m.raycast_program, camera);
    m.draw_volume(m.raycast_program);
  });

  RenderResult result;
  // 3. CPU colouring of the surface.
  if (s.surface_scalar.value && m.has_volume) m.colour_surface(s, camera, result);

  // 4. Lighting.
  m.queue.timed("preview/shade", [&] {
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, m.final_target.get());
    glViewport(0, 0, s.width, s.height);
    const gpu::Program& p = m.shade_program;
    p.use();
    set_camera(p, camera);
    glBindTextureUnit(TS_PREVIEW_UNIT_ALBEDO, m.albedo.get());
    glBindTextureUnit(TS_PREVIEW_UNIT_NORMAL, m.normal.get());
    glBindTextureUnit(TS_PREVIEW_UNIT_DEPTH, m.depth.get());
    glBindTextureUnit(TS_PREVIEW_UNIT_SHADOW, s.shadows ? m.shadow_depth.get() : 0);
    p.set("shadows", s.shadows ? 1 : 0);
    if (s.shadows) {
      set_matrix(p, "light_view_projection", light_camera.view_projection);
      const double texel = 2.02 * radius / m.shadow_size;
      p.set("shadow_texel", static_cast<float>(texel));
      // Light depth is linear over the near-far range (about 2 radius): one texel of slack.
      p.set("shadow_bias", static_cast<float>(texel / (2.0 * radius)));
      p.set("shadow_texel_uv", 1.0f / m.shadow_size, 1.0f / m.shadow_size);
    }
    if (m.has_volume) m.bind_volume(p);
    p.set("has_volume", m.has_volume ? 1 : 0);
    set_vec3(p, "light_dir", light);
    set_vec3(p, "world_up", up);
    p.set("ground", s.ground ? 1 : 0);
    p.set("ground_level", static_cast<float>(ground_level));
    const Eigen::Vector3d center = content.center() - origin;
    set_vec3(p, "ground_center", Eigen::Vector3d(center - (up.dot(center) - ground_level) * up));
    p.set("ground_radius", static_cast<float>(2.5 * 0.5 * content.size().norm()));
    set_vec3(p, "ground_color", Eigen::Vector3f(0.88f, 0.88f, 0.87f));
    set_vec3(p, "background_top", Eigen::Vector3f(0.97f, 0.97f, 0.98f));
    set_vec3(p, "background_bottom", Eigen::Vector3f(0.80f, 0.82f, 0.86f));
    p.set("transparent", s.alpha ? 1 : 0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    m.check("preview shade");
  });

  const std::size_t pixels = static_cast<std::size_t>(s.width) * s.height;
  std::vector<std::uint8_t> rgba(4 * pixels);
  glGetTextureImage(m.final_color.get(), 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(rgba.size()), rgba.data());
  result.image.width = s.width;
  result.image.height = s.height;
  result.image.alpha = s.alpha;
  result.image.rgba = flip_rows(rgba, s.width, s.height, 4);
  if (s.keep_buffers) {
    std::vector<float> nl(4 * pixels);
    glGetTextureImage(m.normal.get(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(nl.size() * 4), nl.data());
    nl = flip_rows(nl, s.width, s.height, 4);
    result.layers.resize(pixels);
    result.normals.resize(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
      result.layers[i] = static_cast<Layer>(static_cast<int>(nl[4 * i + 3] + 0.5f));
      result.normals[i] = Eigen::Vector3f(nl[4 * i], nl[4 * i + 1], nl[4 * i + 2]);
    }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glBindVertexArray(0);
  glUseProgram(0);
  m.check("preview read back");
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string Renderer::timing_report() { return impl_->queue.timing_report(); }

}  // namespace ts::preview
