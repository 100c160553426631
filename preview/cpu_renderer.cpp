#include "preview/cpu_renderer.h"

#include <fmt/format.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include "core/error.h"
#include "preview/colors.h"
#include "preview/cpu_field.h"
#include "preview/frame.h"
#include "shaders/preview/look.h"

namespace ts::preview {
namespace {

// Pixels are handed to TBB in tiles this many a side: a tile shares one field reader (its node
// caches) and, in the splatter, one list of the spheres that touch it.
constexpr int kTile = 32;

// One G-buffer texel, as the GL pass's targets hold it. Rows bottom-up, as GL's window coordinates.
struct Texel {
  float depth = 1.0f;                   // window depth, 0 near .. 1 far (1: nothing)
  Layer layer = Layer::Background;
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // unit, world
  Eigen::Vector3f albedo = Eigen::Vector3f::Zero();  // sRGB, quantised to 8 bits as the RGBA8 target
};

struct Buffer {
  int width = 0, height = 0;
  std::vector<Texel> texels;
  Buffer(int w, int h) : width(w), height(h), texels(static_cast<std::size_t>(w) * h) {}
  Texel& at(int x, int y) { return texels[static_cast<std::size_t>(y) * width + x]; }
  const Texel& at(int x, int y) const { return texels[static_cast<std::size_t>(y) * width + x]; }
};

Eigen::Vector3f quantise(const Eigen::Vector3f& c) {
  return (c.array().max(0.0f).min(1.0f) * 255.0f).round() / 255.0f;
}

// camera.glsl's world_from_window: the point at window position (pixels) and depth (0..1), relative.
Eigen::Vector3d world_from_window(const CameraState& c, double x, double y, double depth) {
  const Eigen::Vector4d w = c.inverse * Eigen::Vector4d(2.0 * x / c.width - 1.0, 2.0 * y / c.height - 1.0,
                                                        2.0 * depth - 1.0, 1.0);
  return w.head<3>() / w.w();
}

// camera.glsl's window_depth.
double window_depth(const CameraState& c, const Eigen::Vector3d& p) {
  const Eigen::Vector4d clip = c.view_projection * p.homogeneous();
  return 0.5 * clip.z() / clip.w() + 0.5;
}

// The ray through a pixel's window position: from the near plane towards the far plane.
struct Ray {
  Eigen::Vector3d start, dir;
};
Ray window_ray(const CameraState& c, double x, double y) {
  const Eigen::Vector3d start = world_from_window(c, x, y, 0.0);
  return {start, (world_from_window(c, x, y, 1.0) - start).normalized()};
}

// Calls f(x, y) for every pixel of the buffer, tile by tile in parallel; make() gives each tile its
// own per-tile state, passed to f.
template <typename Make, typename F>
void for_each_tile(int width, int height, Make make, F f) {
  tbb::parallel_for(tbb::blocked_range2d<int>(0, height, kTile, 0, width, kTile), [&](const auto& r) {
    auto state = make();
    for (int y = r.rows().begin(); y < r.rows().end(); ++y)
      for (int x = r.cols().begin(); x < r.cols().end(); ++x) f(state, x, y);
  });
}

struct Sphere {
  Eigen::Vector3d center;  // relative to the frame's origin [m]
  double radius = 0.0;     // m
  Eigen::Vector3f color;   // sRGB, 8-bit
};

// The pixels a sphere may cover, inclusive, clipped to the image; nullopt when none. The projected
// corners of its bounding cube hold the projected sphere when the cube lies in front of the eye;
// otherwise the whole image is searched.
struct PixelBox {
  int x0, y0, x1, y1;
};
std::optional<PixelBox> screen_box(const CameraState& c, const Sphere& s) {
  if (!c.ortho && (s.center - c.eye).norm() <= 1.0001 * s.radius) return std::nullopt;  // as particles.vert
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  bool behind = false;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d corner = s.center + s.radius * Eigen::Vector3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
    const Eigen::Vector4d clip = c.view_projection * corner.homogeneous();
    if (clip.w() <= 1e-12) behind = true;
    const Eigen::Vector2d ndc = clip.head<2>() / clip.w();
    lo = lo.cwiseMin(ndc);
    hi = hi.cwiseMax(ndc);
  }
  PixelBox b{0, 0, c.width - 1, c.height - 1};
  if (!behind) {  // pixel centres x + 0.5 within the box, one pixel of slack for rounding
    b.x0 = std::max(b.x0, static_cast<int>(std::floor(0.5 * (lo.x() + 1.0) * c.width)) - 1);
    b.y0 = std::max(b.y0, static_cast<int>(std::floor(0.5 * (lo.y() + 1.0) * c.height)) - 1);
    b.x1 = std::min(b.x1, static_cast<int>(std::ceil(0.5 * (hi.x() + 1.0) * c.width)));
    b.y1 = std::min(b.y1, static_cast<int>(std::ceil(0.5 * (hi.y() + 1.0) * c.height)));
  }
  if (b.x0 > b.x1 || b.y0 > b.y1) return std::nullopt;
  return b;
}

// One sphere at one pixel: the exact ray-sphere hit (particles.frag), depth-tested as GL_LESS, so
// of equal depths the sphere drawn first stays, as in the GL draw order.
void splat_pixel(const CameraState& c, const Sphere& s, bool depth_only, int x, int y, Texel& texel) {
  const Ray ray = window_ray(c, x + 0.5, y + 0.5);
  const Eigen::Vector3d oc = ray.start - s.center;
  const double b = oc.dot(ray.dir), disc = b * b - (oc.squaredNorm() - s.radius * s.radius);
  if (disc < 0.0) return;
  const Eigen::Vector3d p = ray.start + (-b - std::sqrt(disc)) * ray.dir;
  const double depth = window_depth(c, p);
  if (!(depth >= 0.0 && depth < texel.depth)) return;
  texel.depth = static_cast<float>(depth);
  if (depth_only) return;
  texel.layer = Layer::Particle;
  texel.normal = ((p - s.center) / s.radius).cast<float>();
  texel.albedo = s.color;
}

// The splatter: spheres binned into the tiles their screen boxes touch, in index order, then the
// tiles drawn in parallel, each sphere over its box's pixels in the tile.
void splat(const std::vector<Sphere>& spheres, const CameraState& c, bool depth_only, Buffer& target) {
  std::vector<std::optional<PixelBox>> boxes(spheres.size());
  tbb::parallel_for(std::size_t{0}, spheres.size(), [&](std::size_t i) { boxes[i] = screen_box(c, spheres[i]); });
  const int tiles_x = (target.width + kTile - 1) / kTile, tiles_y = (target.height + kTile - 1) / kTile;
  std::vector<std::vector<std::uint32_t>> bins(static_cast<std::size_t>(tiles_x) * tiles_y);
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    if (!boxes[i]) continue;
    for (int ty = boxes[i]->y0 / kTile; ty <= boxes[i]->y1 / kTile; ++ty)
      for (int tx = boxes[i]->x0 / kTile; tx <= boxes[i]->x1 / kTile; ++tx)
        bins[static_cast<std::size_t>(ty) * tiles_x + tx].push_back(static_cast<std::uint32_t>(i));
  }
  tbb::parallel_for(std::size_t{0}, bins.size(), [&](std::size_t tile) {
    const int tx = static_cast<int>(tile % tiles_x) * kTile, ty = static_cast<int>(tile / tiles_x) * kTile;
    for (std::uint32_t i : bins[tile]) {
      const PixelBox& b = *boxes[i];
      for (int y = std::max(b.y0, ty); y <= std::min(b.y1, ty + kTile - 1); ++y)
        for (int x = std::max(b.x0, tx); x <= std::min(b.x1, tx + kTile - 1); ++x)
          splat_pixel(c, spheres[i], depth_only, x, y, target.at(x, y));
    }
  });
}

// The SDF's share of a view: raycast.frag per pixel, the field in voxel units.
struct RayCast {
  const CpuField& field;
  const CameraState& camera;
  Eigen::Vector3d voxel_origin;  // the spec's voxel (0, 0, 0), relative to the frame's origin [m]
  bool limit_by_particles = false;
  bool depth_only = false;
  Eigen::Vector3f color;  // sRGB, 8-bit

  void pixel(CpuField::Reader& reader, int x, int y, Texel& texel) const;
};

void RayCast::pixel(CpuField::Reader& reader, int x, int y, Texel& texel) const {
  const double h = field.spec().voxel_size;
  const Ray ray = window_ray(camera, x + 0.5, y + 0.5);
  const Eigen::Vector3d o = (ray.start - voxel_origin) / h;
  // The slab test against the voxel-centre box [0, dims - 1], which the GL pass rasterises.
  const Eigen::Vector3d safe = ray.dir.unaryExpr([](double d) { return std::abs(d) < 1e-20 ? 1e-20 : d; });
  const Eigen::Vector3d t0 = -o.cwiseQuotient(safe);
  const Eigen::Vector3d t1 = ((field.spec().dims.cast<double>().array() - 1.0).matrix() - o).cwiseQuotient(safe);
  const double t = std::max(t0.cwiseMin(t1).maxCoeff(), 0.0);
  double t_exit = t0.cwiseMax(t1).minCoeff();
  if (limit_by_particles && texel.depth < 1.0f) {
    const Eigen::Vector3d particle = world_from_window(camera, x + 0.5, y + 0.5, texel.depth);
    t_exit = std::min(t_exit, (particle - ray.start).dot(ray.dir) / h);
  }
  if (t >= t_exit) return;
  const bool entered_inside = reader.sdf_at(o + t * ray.dir) <= 0.0;  // the near plane cuts the solid
  const std::optional<double> t_hit = entered_inside ? std::optional<double>(t)
                                                     : reader.first_crossing(o, ray.dir, t, t_exit);
  if (!t_hit) return;
  const double depth = window_depth(camera, ray.start + ray.dir * (*t_hit * h));
  if (!(depth < texel.depth)) return;
  texel.depth = static_cast<float>(depth);
  if (depth_only) return;
  texel.layer = Layer::Surface;
  texel.normal = (entered_inside ? Eigen::Vector3d(-ray.dir) : reader.normal(o + *t_hit * ray.dir)).cast<float>();
  texel.albedo = color;
}

void ray_cast(const RayCast& cast, Buffer& target) {
  for_each_tile(
      target.width, target.height, [&] { return CpuField::Reader(cast.field); },
      [&](CpuField::Reader& reader, int x, int y) { cast.pixel(reader, x, y, target.at(x, y)); });
}

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}
Eigen::Vector3d to_linear(const Eigen::Vector3d& c) { return c.array().pow(TS_PREVIEW_GAMMA); }
Eigen::Vector3d to_srgb(const Eigen::Vector3d& c) {
  return c.array().max(0.0).min(1.0).pow(1.0 / TS_PREVIEW_GAMMA);
}

// The lighting pass, shade.frag line for line.
struct Shading {
  const RenderSettings& settings;
  const Frame& frame;
  const Buffer* shadow_map;  // null without shadows
  const CpuField* field;     // null without an SDF
  Eigen::Vector3d voxel_origin;

  double shadow_compare(double u, double v, double ref) const;
  double light_visibility(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const;
  Eigen::Vector3d lit(const Eigen::Vector3d& base, const Eigen::Vector3d& n, double visibility,
                      const Eigen::Vector3d& view, double specular, double occlusion) const;
  Eigen::Vector4d surface(CpuField::Reader* reader, const Texel& texel, int x, int y) const;
  Eigen::Vector4d backdrop(int x, int y) const;
};

// One lookup of a sampler2DShadow with linear filtering: the depth comparisons (GL_LEQUAL) of the
// four texels around (u, v), clamped at the edges, weighted bilinearly.
double Shading::shadow_compare(double u, double v, double ref) const {
  const Buffer& map = *shadow_map;
  const double fx = u * map.width - 0.5, fy = v * map.height - 0.5;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const double ax = fx - x0, ay = fy - y0;
  const auto lit = [&](int x, int y) {
    return ref <= map.at(std::clamp(x, 0, map.width - 1), std::clamp(y, 0, map.height - 1)).depth ? 1.0 : 0.0;
  };
  return (1.0 - ay) * ((1.0 - ax) * lit(x0, y0) + ax * lit(x0 + 1, y0)) +
         ay * ((1.0 - ax) * lit(x0, y0 + 1) + ax * lit(x0 + 1, y0 + 1));
}

double Shading::light_visibility(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
  if (!shadow_map) return 1.0;
  const Eigen::Vector3d q = p + n * (TS_PREVIEW_SHADOW_OFFSET_TEXELS * frame.shadow_texel);
  const Eigen::Vector4d c = frame.light_camera.view_projection * q.homogeneous();
  const Eigen::Vector3d s = (0.5 * c.head<3>() / c.w()).array() + 0.5;
  if (s.x() < 0.0 || s.y() < 0.0 || s.x() > 1.0 || s.y() > 1.0) return 1.0;
  const double ref = std::min(s.z(), 1.0) - frame.shadow_bias;
  const double step = 1.0 / frame.shadow_size;
  double lit = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) lit += shadow_compare(s.x() + x * step, s.y() + y * step, ref);
  return lit / 9.0;
}

Eigen::Vector3d Shading::lit(const Eigen::Vector3d& base, const Eigen::Vector3d& n, double visibility,
                             const Eigen::Vector3d& view, double specular, double occlusion) const {
  const double diffuse = std::max(n.dot(frame.light), 0.0);
  const Eigen::Vector3d h = (frame.light + view).normalized();
  const double spec = diffuse > 0.0 ? specular * std::pow(std::max(n.dot(h), 0.0), TS_PREVIEW_SPECULAR_POWER) : 0.0;
  const double up = 0.5 + 0.5 * n.dot(frame.up);
  const double ambient = TS_PREVIEW_AMBIENT_DOWN + (TS_PREVIEW_AMBIENT_UP - TS_PREVIEW_AMBIENT_DOWN) * up;
  const double fill = TS_PREVIEW_CAMERA_FILL * std::max(n.dot(view), 0.0);
  return base * ((ambient + fill) * occlusion + TS_PREVIEW_DIFFUSE * diffuse * visibility) +
         Eigen::Vector3d::Constant(spec * visibility);
}

Eigen::Vector4d Shading::surface(CpuField::Reader* reader, const Texel& texel, int x, int y) const {
  const CameraState& c = frame.camera;
  const Ray ray = window_ray(c, x + 0.5, y + 0.5);
  const Eigen::Vector3d p = world_from_window(c, x + 0.5, y + 0.5, texel.depth);
  const Eigen::Vector3d n = texel.normal.cast<double>().normalized();
  const bool is_surface = texel.layer == Layer::Surface;
  double occlusion = 1.0;
  if (is_surface && reader) {
    const Eigen::Vector3d u = (p - voxel_origin) / field->spec().voxel_size;
    occlusion = std::clamp(1.0 - TS_PREVIEW_OCCLUSION_GAIN * reader->occlusion(u, n), 0.0, 1.0);
  }
  const double specular = is_surface ? TS_PREVIEW_SPECULAR_SURFACE : TS_PREVIEW_SPECULAR_PARTICLE;
  const Eigen::Vector3d color =
      lit(to_linear(texel.albedo.cast<double>()), n, light_visibility(p, n), -ray.dir, specular, occlusion);
  const Eigen::Vector3d srgb = to_srgb(color);
  return {srgb.x(), srgb.y(), srgb.z(), 1.0};
}

// Where nothing is drawn: the sky gradient, and the ground plane catching the shadows.
Eigen::Vector4d Shading::backdrop(int x, int y) const {
  const CameraState& c = frame.camera;
  const Ray ray = window_ray(c, x + 0.5, y + 0.5);
  const double height = (y + 0.5) / c.height;
  const Eigen::Vector3d sky =
      (kBackgroundBottom + (kBackgroundTop - kBackgroundBottom) * static_cast<float>(height)).cast<double>();
  const Eigen::Vector4d nothing = settings.alpha ? Eigen::Vector4d::Zero() : Eigen::Vector4d(sky.x(), sky.y(), sky.z(), 1.0);
  const double along = frame.up.dot(ray.dir);
  if (!settings.ground || along >= 0.0) return nothing;
  const double t = (frame.ground_level - frame.up.dot(ray.start)) / along;
  if (t <= 0.0) return nothing;
  const Eigen::Vector3d g = ray.start + t * ray.dir;
  const double fade = 1.0 - smoothstep(TS_PREVIEW_GROUND_FADE_START * frame.ground_fade, frame.ground_fade,
                                       (g - frame.ground_center).norm());
  if (fade <= 0.0) return nothing;
  const double visibility = light_visibility(g, frame.up);
  if (settings.alpha) return {0.0, 0.0, 0.0, TS_PREVIEW_GROUND_SHADOW_ALPHA * fade * (1.0 - visibility)};
  const double diffuse = std::max(frame.up.dot(frame.light), 0.0);
  const Eigen::Vector3d lit_ground =
      to_linear(kGroundColor.cast<double>()) * (TS_PREVIEW_GROUND_AMBIENT + TS_PREVIEW_GROUND_DIFFUSE * diffuse * visibility);
  const Eigen::Vector3d mixed = sky + (to_srgb(lit_ground) - sky) * fade;
  return {mixed.x(), mixed.y(), mixed.z(), 1.0};
}

std::uint8_t unorm8(double v) { return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(v, 0.0, 1.0))); }

}  // namespace

struct CpuRenderer::Impl {
  bool timings = false;
  std::map<std::string, std::pair<int, double>> pass_seconds;  // name -> (calls, seconds)
  std::optional<CpuField> field;
  Aabb surface_box, volume_box;
  Particles particles;
  Aabb particle_box;

  template <typename F>
  void timed(const char* name, F f) {
    const auto start = std::chrono::steady_clock::now();
    f();
    if (!timings) return;
    auto& entry = pass_seconds[name];
    ++entry.first;
    entry.second += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  std::vector<Sphere> spheres(const RenderSettings& s, const Frame& f) const;
  // The SDF's voxel (0, 0, 0) relative to the frame's origin [m].
  Eigen::Vector3d voxel_origin(const Frame& f) const {
    return field ? Eigen::Vector3d(field->spec().origin - f.origin) : Eigen::Vector3d::Zero();
  }
  Buffer shadow_pass(const RenderSettings& s, const Frame& f, const std::vector<Sphere>& spheres);
  Buffer gbuffer_pass(const RenderSettings& s, const Frame& f, const std::vector<Sphere>& spheres);
  void colour_surface(const RenderSettings& s, const Frame& f, Buffer& g, RenderResult& result) const;
  void lighting_pass(const RenderSettings& s, const Frame& f, const Buffer& g, const Buffer* shadow, Image& image);
};

std::vector<Sphere> CpuRenderer::Impl::spheres(const RenderSettings& s, const Frame& f) const {
  const std::size_t n = particles.centers.size();
  std::vector<Sphere> out(n);
  const bool one_radius = particles.radii.size() == 1;
  const Eigen::Vector3f color = quantise(s.particle_color);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    out[i].center = particles.centers[i] - f.origin;
    out[i].radius = particles.radii[one_radius ? 0 : i];
    if (particles.colors.empty()) {
      out[i].color = color;
    } else {
      const std::uint32_t c = particles.colors[i];
      out[i].color = Eigen::Vector3f(static_cast<float>(c & 0xffu), static_cast<float>((c >> 8) & 0xffu),
                                     static_cast<float>((c >> 16) & 0xffu)) /
                     255.0f;
    }
  });
  return out;
}

// 1. The key light's shadow map: particles and the SDF, depth only.
Buffer CpuRenderer::Impl::shadow_pass(const RenderSettings&, const Frame& f, const std::vector<Sphere>& spheres) {
  Buffer map(f.shadow_size, f.shadow_size);
  timed("preview/shadow map (CPU)", [&] {
    splat(spheres, f.light_camera, true, map);
    if (field) ray_cast({*field, f.light_camera, voxel_origin(f), false, true, {}}, map);
  });
  return map;
}

// 2. The G-buffer: particles, then the SDF marched up to them.
Buffer CpuRenderer::Impl::gbuffer_pass(const RenderSettings& s, const Frame& f, const std::vector<Sphere>& spheres) {
  Buffer g(s.width, s.height);
  timed("preview/particles (CPU)", [&] { splat(spheres, f.camera, false, g); });
  if (field) {
    timed("preview/ray cast (CPU)", [&] {
      ray_cast({*field, f.camera, voxel_origin(f), !spheres.empty(), false, quantise(s.surface_color)}, g);
    });
  }
  return g;
}

// 3. The surface coloured by the scalar at each visible surface pixel's world position.
void CpuRenderer::Impl::colour_surface(const RenderSettings& s, const Frame& f, Buffer& g, RenderResult& result) const {
  std::vector<double> values(g.texels.size(), std::numeric_limits<double>::quiet_NaN());
  tbb::parallel_for(0, g.height, [&](int y) {
    for (int x = 0; x < g.width; ++x) {
      Texel& texel = g.at(x, y);
      if (texel.layer != Layer::Surface) continue;
      const Eigen::Vector3d p = world_from_window(f.camera, x + 0.5, y + 0.5, texel.depth) + f.origin;
      const double value = s.surface_scalar.value(p);
      values[static_cast<std::size_t>(y) * g.width + x] = value;
      texel.albedo = quantise(viridis(value / s.surface_scalar.max_value));
    }
  });
  result.scalar = summarize_scalar(values);
}

// 4. Lighting, into the image (top row first).
void CpuRenderer::Impl::lighting_pass(const RenderSettings& s, const Frame& f, const Buffer& g, const Buffer* shadow,
                                      Image& image) {
  image.width = s.width;
  image.height = s.height;
  image.alpha = s.alpha;
  image.rgba.assign(4 * g.texels.size(), 0);
  const Shading shading{s, f, shadow, field ? &*field : nullptr, voxel_origin(f)};
  timed("preview/shade (CPU)", [&] {
    for_each_tile(
        g.width, g.height,
        [&] { return field ? std::optional<CpuField::Reader>(std::in_place, *field) : std::nullopt; },
        [&](std::optional<CpuField::Reader>& reader, int x, int y) {
          const Texel& texel = g.at(x, y);
          const Eigen::Vector4d c = texel.layer == Layer::Background
                                        ? shading.backdrop(x, y)
                                        : shading.surface(reader ? &*reader : nullptr, texel, x, y);
          std::uint8_t* out = image.pixel(x, s.height - 1 - y);
          for (int k = 0; k < 4; ++k) out[k] = unorm8(c[k]);
        });
  });
}

CpuRenderer::CpuRenderer(bool timings) : impl_(std::make_unique<Impl>()) { impl_->timings = timings; }
CpuRenderer::~CpuRenderer() = default;

void CpuRenderer::load_volume(SdfVolume volume) {
  impl_->field.emplace(volume);
  impl_->surface_box = volume.surface;
  impl_->volume_box = volume.world_box();
}

void CpuRenderer::set_particles(const Particles& particles) {
  impl_->particle_box = particle_box(particles);
  impl_->particles = particles;
}

Aabb CpuRenderer::content_box() const {
  return preview::content_box(impl_->field ? std::optional<Aabb>(impl_->surface_box) : std::nullopt,
                              impl_->particle_box);
}

void CpuRenderer::check_image_size(int width, int height) const {
  if (width < 1 || height < 1) {
    throw InputError(fmt::format("image size {} x {}: both sides must be at least 1 pixel", width, height));
  }
  if (width > kMaxImageSide || height > kMaxImageSide) {
    throw InputError(fmt::format("image size {} x {} exceeds the CPU renderer's largest image, {} x {}", width,
                                 height, kMaxImageSide, kMaxImageSide));
  }
}

RenderResult CpuRenderer::render(const RenderSettings& s) {
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  check_image_size(s.width, s.height);
  const Frame frame = plan_frame(s, content_box(), m.field ? std::optional<Aabb>(m.volume_box) : std::nullopt,
                                 kMaxImageSide);
  const std::vector<Sphere> spheres = m.spheres(s, frame);
  std::optional<Buffer> shadow;
  if (s.shadows) shadow = m.shadow_pass(s, frame, spheres);
  Buffer g = m.gbuffer_pass(s, frame, spheres);
  RenderResult result;
  if (s.surface_scalar.value && m.field) m.colour_surface(s, frame, g, result);
  m.lighting_pass(s, frame, g, shadow ? &*shadow : nullptr, result.image);
  if (s.keep_buffers) {
    result.layers.resize(g.texels.size());
    result.normals.resize(g.texels.size());
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        const std::size_t out = static_cast<std::size_t>(s.height - 1 - y) * s.width + x;
        result.layers[out] = g.at(x, y).layer;
        result.normals[out] = g.at(x, y).normal;
      }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::vector<PassTime> CpuRenderer::pass_times() {
  std::vector<PassTime> passes;
  for (const auto& [name, entry] : impl_->pass_seconds) {
    passes.push_back({name, static_cast<std::size_t>(entry.first), 1e3 * entry.second});
  }
  return passes;
}

std::string CpuRenderer::timing_report() {
  double sum = 0.0;
  for (const auto& [name, entry] : impl_->pass_seconds) sum += entry.second;
  std::string out = fmt::format("{:<40} {:>8} {:>12} {:>10}\n", "CPU pass", "calls", "total ms", "share");
  for (const auto& [name, entry] : impl_->pass_seconds) {
    out += fmt::format("{:<40} {:>8} {:>12.3f} {:>9.1f}%\n", name, entry.first, 1e3 * entry.second,
                       sum > 0 ? 100.0 * entry.second / sum : 0.0);
  }
  out += fmt::format("{:<40} {:>8} {:>12.3f}\n", "total", "", 1e3 * sum);
  return out;
}

std::string CpuRenderer::device() const {
  return fmt::format("the CPU ({} TBB threads)", tbb::this_task_arena::max_concurrency());
}

}  // namespace ts::preview
