#include "sdf/scan_convert.h"

#include <fmt/format.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <chrono>
#include <iterator>
#include <optional>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "gpu/gl.h"
#include "gpu/layouts.h"

namespace ts::sdf {
namespace {

using gpu::layout::SdfPrism;
using gpu::layout::SdfTriangle;
using gpu::layout::vec4;

// Layers one draw covers: the geometry shader's INVOCATIONS * LAYERS_PER_INVOCATION.
constexpr int kLayersPerDraw = 32 * 4;
// A grown corner farther than this many margins from its vertex marks a needle (tiny angle).
constexpr double kMaxMiter = 4.0;
// Colour of voxels no fragment reached.
constexpr float kUntouched = 1e30f;

vec4 to_vec4(const Eigen::Vector3d& v, double w = 0.0) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()), static_cast<float>(w)};
}

struct GpuGeometry {
  std::vector<SdfTriangle> triangles;
  std::vector<SdfPrism> prisms;
  std::vector<double> zmin, zmax;  // prism extent along z [voxels]
  std::vector<std::uint32_t> drawn;  // triangles that have a prism (not degenerate)
  std::size_t degenerate = 0, needles = 0;
};

// The prism base: the triangle grown by `margin` in its plane. Offsetting each edge outward by the
// margin moves vertex i by margin * (n1 + n2) / (1 + n1.n2) (n1, n2 the outward normals of its two
// edges); for slivers that miter explodes, so they get their grown in-plane bounding rectangle.
void build_prism_base(const Eigen::Vector3d (&v)[3], const Eigen::Vector3d& n, double margin, SdfPrism& prism,
                      bool& needle) {
  Eigen::Vector3d out[3];
  for (int e = 0; e < 3; ++e) out[e] = (v[(e + 1) % 3] - v[e]).cross(n).normalized();
  Eigen::Vector3d grown[3];
  needle = false;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d& n1 = out[(i + 2) % 3];  // edge ending at vertex i
    const Eigen::Vector3d& n2 = out[i];            // edge starting at vertex i
    const double denominator = 1.0 + n1.dot(n2);
    const Eigen::Vector3d miter = denominator > 1e-12 ? Eigen::Vector3d((n1 + n2) / denominator) : Eigen::Vector3d(1e9, 0, 0);
    if (miter.norm() > kMaxMiter) needle = true;
    grown[i] = v[i] + margin * miter;
  }
  if (!needle) {
    for (int i = 0; i < 3; ++i) prism.corner[i] = to_vec4(grown[i]);
    prism.corner[3] = prism.corner[2];
    prism.corner[0].w = 3.0f;
    return;
  }
  int longest = 0;
  for (int e = 1; e < 3; ++e)
    if ((v[(e + 1) % 3] - v[e]).squaredNorm() > (v[(longest + 1) % 3] - v[longest]).squaredNorm()) longest = e;
  const Eigen::Vector3d u = (v[(longest + 1) % 3] - v[longest]).normalized();
  const Eigen::Vector3d w = n.cross(u);
  double u0 = 1e300, u1 = -1e300, w0 = 1e300, w1 = -1e300;
  for (const auto& p : v) {
    const Eigen::Vector3d d = p - v[0];
    u0 = std::min(u0, d.dot(u)), u1 = std::max(u1, d.dot(u));
    w0 = std::min(w0, d.dot(w)), w1 = std::max(w1, d.dot(w));
  }
  u0 -= margin, u1 += margin, w0 -= margin, w1 += margin;
  const Eigen::Vector3d corners[4] = {v[0] + u0 * u + w0 * w, v[0] + u1 * u + w0 * w, v[0] + u1 * u + w1 * w,
                                      v[0] + u0 * u + w1 * w};
  for (int i = 0; i < 4; ++i) prism.corner[i] = to_vec4(corners[i]);
  prism.corner[0].w = 4.0f;
}

GpuGeometry build_geometry(const TriangleMesh& mesh, const Pseudonormals& normals, const GridSpec& spec,
                           double margin) {
  GpuGeometry g;
  const std::size_t count = mesh.triangle_count();
  g.triangles.resize(count);
  g.prisms.resize(count);
  g.zmin.resize(count);
  g.zmax.resize(count);
  for (std::size_t t = 0; t < count; ++t) {
    // Grid-local voxel units, computed in double: the error in voxels is then independent of where
    // the mesh sits and how large it is.
    Eigen::Vector3d v[3];
    for (int k = 0; k < 3; ++k) v[k] = spec.to_voxel(mesh.vertices[mesh.triangles[t][k]]);
    SdfTriangle& tri = g.triangles[t];
    for (int k = 0; k < 3; ++k) {
      tri.vertex[k] = to_vec4(v[k]);
      tri.edge_normal[k] = to_vec4(normals.edge[t][static_cast<std::size_t>(k)]);
      tri.vertex_normal[k] = to_vec4(normals.vertex[t][static_cast<std::size_t>(k)]);
    }
    const Eigen::Vector3d cross = (v[1] - v[0]).cross(v[2] - v[0]);
    const double longest = std::max({(v[1] - v[0]).norm(), (v[2] - v[1]).norm(), (v[0] - v[2]).norm()});
    const bool degenerate = !(cross.norm() > 1e-12 * std::max(longest * longest, 1e-300));
    tri.face_normal = to_vec4(normals.face[t], degenerate ? 0.0 : 1.0);
    if (degenerate) {
      ++g.degenerate;
      continue;
    }
    const Eigen::Vector3d n = cross.normalized();
    bool needle = false;
    build_prism_base(v, n, margin, g.prisms[t], needle);
    g.prisms[t].normal_margin = to_vec4(n, margin);
    if (needle) ++g.needles;
    double lo = 1e300, hi = -1e300;
    const int corners = static_cast<int>(g.prisms[t].corner[0].w);
    for (int k = 0; k < corners; ++k) {
      const double z = g.prisms[t].corner[k].z;
      lo = std::min(lo, z - margin * std::abs(n.z()));
      hi = std::max(hi, z + margin * std::abs(n.z()));
    }
    g.zmin[t] = lo;
    g.zmax[t] = hi;
    g.drawn.push_back(static_cast<std::uint32_t>(t));
  }
  return g;
}

// Geometry-shader variants by invocation count (4 layers each): a prism goes to the first variant
// that covers its layer span, so small triangles (most of a fine mesh, spanning ~2 * margin layers)
// do not pay for 32 mostly idle invocations. The last is the full draw block (kLayersPerDraw).
constexpr int kVariantInvocations[] = {4, 32};
constexpr std::size_t kVariants = std::size(kVariantInvocations);
static_assert(4 * kVariantInvocations[kVariants - 1] == kLayersPerDraw, "the last variant covers a draw block");

// Indices (4 per prism, GL_LINES_ADJACENCY) grouped by the block of `block` z-layers they touch and,
// within a block, by variant: list kVariants * b + v holds the block's prisms for variant v.
struct DrawLists {
  std::vector<std::uint32_t> indices;
  std::vector<std::size_t> begin;  // list l uses indices[begin[l] .. begin[l+1])
};

DrawLists bucket_by_block(const GpuGeometry& g, int dims_z, int block) {
  const int blocks = (dims_z + block - 1) / block;
  std::vector<std::size_t> counts(kVariants * static_cast<std::size_t>(blocks) + 1, 0);
  auto block_range = [&](std::uint32_t t) {
    const int lo = std::clamp(static_cast<int>(std::ceil(g.zmin[t])), 0, dims_z - 1);
    const int hi = std::clamp(static_cast<int>(std::floor(g.zmax[t])), 0, dims_z - 1);
    const bool empty = std::floor(g.zmax[t]) < 0 || std::ceil(g.zmin[t]) > dims_z - 1 || hi < lo;
    std::size_t variant = 0;
    while (variant + 1 < kVariants && hi - lo + 1 > 4 * kVariantInvocations[variant]) ++variant;
    return std::tuple{lo / block, hi / block, empty, variant};
  };
  for (std::uint32_t t : g.drawn) {
    auto [b0, b1, empty, variant] = block_range(t);
    if (!empty)
      for (int b = b0; b <= b1; ++b) counts[kVariants * static_cast<std::size_t>(b) + variant + 1] += 4;
  }
  DrawLists lists;
  lists.begin.resize(counts.size());
  for (std::size_t l = 1; l < counts.size(); ++l) lists.begin[l] = lists.begin[l - 1] + counts[l];
  lists.indices.resize(lists.begin.back());
  std::vector<std::size_t> cursor(lists.begin.begin(), lists.begin.end() - 1);
  for (std::uint32_t t : g.drawn) {
    auto [b0, b1, empty, variant] = block_range(t);
    if (empty) continue;
    for (int b = b0; b <= b1; ++b)
      for (std::uint32_t k = 0; k < 4; ++k)
        lists.indices[cursor[kVariants * static_cast<std::size_t>(b) + variant]++] = 4 * t + k;
  }
  return lists;
}

// A layered render target of `layers` z-slices: RGBA32F value + 32F depth.
class SlabTarget {
 public:
  SlabTarget(int width, int height, int layers) {
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &color_);
    glTextureStorage3D(color_, 1, GL_RGBA32F, width, height, layers);
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &depth_);
    glTextureStorage3D(depth_, 1, GL_DEPTH_COMPONENT32F, width, height, layers);
    if (glGetError() == GL_OUT_OF_MEMORY) release(), throw GpuError("out of GPU memory for an SDF slab");
    glCreateFramebuffers(1, &framebuffer_);
    glNamedFramebufferTexture(framebuffer_, GL_COLOR_ATTACHMENT0, color_, 0);
    glNamedFramebufferTexture(framebuffer_, GL_DEPTH_ATTACHMENT, depth_, 0);
    if (glCheckNamedFramebufferStatus(framebuffer_, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      release();
      throw GpuError("the layered SDF render target is incomplete on this GPU");
    }
  }
  ~SlabTarget() { release(); }
  SlabTarget(const SlabTarget&) = delete;
  SlabTarget& operator=(const SlabTarget&) = delete;
  GLuint framebuffer() const { return framebuffer_; }
  GLuint color() const { return color_; }

 private:
  void release() {
    if (framebuffer_) glDeleteFramebuffers(1, &framebuffer_);
    if (color_) glDeleteTextures(1, &color_);
    if (depth_) glDeleteTextures(1, &depth_);
    framebuffer_ = color_ = depth_ = 0;
  }
  GLuint framebuffer_ = 0, color_ = 0, depth_ = 0;
};

openvdb::FloatGrid::Ptr make_level_set(const GridSpec& spec, float band) {
  if (!(spec.voxel_size >= kMinVdbVoxelSize)) {
    throw InputError("voxel size " + std::to_string(spec.voxel_size) +
                     " is below the smallest OpenVDB can store (1.3e-5 world units); scale the mesh to smaller "
                     "units (e.g. --scale 1000 for millimetres)");
  }
  auto grid = openvdb::FloatGrid::create(band * static_cast<float>(spec.voxel_size));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(spec.voxel_size));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  grid->setName("surface");
  return grid;
}

// Per-voxel state for the signs off the band (dense copy and texture).
enum VoxelState : std::uint8_t { kOffBand = 0, kInBand = 1, kOutside = 2 };

// Off-band voxels reachable from the grid border through off-band voxels become kOutside (+band),
// the ones left kOffBand are inside (-band). 6-connected, so a band of at least one voxel seals the
// surface.
void flood_fill_outside(const GridSpec& s, std::vector<std::uint8_t>& state) {
  std::vector<std::size_t> stack;
  auto push = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= s.dims.x() || j >= s.dims.y() || k >= s.dims.z()) return;
    const std::size_t idx = s.linear_index(i, j, k);
    if (state[idx] != kOffBand) return;
    state[idx] = kOutside;
    stack.push_back(idx);
  };
  for (int k = 0; k < s.dims.z(); ++k)
    for (int j = 0; j < s.dims.y(); ++j)
      for (int i = 0; i < s.dims.x(); ++i)
        if (i == 0 || j == 0 || k == 0 || i == s.dims.x() - 1 || j == s.dims.y() - 1 || k == s.dims.z() - 1) push(i, j, k);
  const std::size_t sx = static_cast<std::size_t>(s.dims.x()), sxy = sx * static_cast<std::size_t>(s.dims.y());
  while (!stack.empty()) {
    const std::size_t idx = stack.back();
    stack.pop_back();
    const int k = static_cast<int>(idx / sxy), j = static_cast<int>((idx % sxy) / sx), i = static_cast<int>(idx % sx);
    push(i - 1, j, k), push(i + 1, j, k), push(i, j - 1, k), push(i, j + 1, k), push(i, j, k - 1), push(i, j, k + 1);
  }
}

void fill_dense_off_band(DenseSdf& dense, const std::vector<std::uint8_t>& state, float band_world) {
  for (std::size_t idx = 0; idx < dense.values.size(); ++idx)
    if (state[idx] != kInBand) dense.values[idx] = {0.0f, 0.0f, 0.0f, state[idx] == kOutside ? band_world : -band_world};
}

// The texture holds the raw slabs (distance in voxels, untouched voxels at kUntouched); one compute
// pass scales the band to world units and gives the rest +-band from a 1-bit inside mask, the only
// data uploaded (1/128 of the field).
void finish_texture(gpu::Queue& queue, const gpu::ShaderLibrary& library, const SdfTexture& texture,
                    const std::vector<std::uint8_t>& state, float band, float voxel_size, std::size_t& peak_bytes) {
  const GridSpec& spec = texture.spec();
  std::vector<std::uint32_t> inside((state.size() + 31) / 32, 0u);
  for (std::size_t idx = 0; idx < state.size(); ++idx)
    if (state[idx] == kOffBand) inside[idx >> 5] |= 1u << (idx & 31u);
  gpu::Buffer bits = gpu::Buffer::from<std::uint32_t>(inside);
  peak_bytes += bits.bytes();
  gpu::Program program = gpu::Program::compute(library, "sdf/finish_texture.comp");
  program.use();
  program.set("dims", spec.dims.x(), spec.dims.y(), spec.dims.z());
  program.set("band", band);
  program.set("voxel_size", voxel_size);
  bits.bind(0);
  glBindImageTexture(0, texture.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
  auto groups = [](int n, int local) { return static_cast<std::uint32_t>((n + local - 1) / local); };
  queue.dispatch(program, groups(spec.dims.x(), 8), groups(spec.dims.y(), 8), groups(spec.dims.z(), 4),
                 GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
}

int choose_slab_layers(const GridSpec& spec, std::size_t budget) {
  const std::size_t per_layer = bytes_per_layer(spec);
  const int fit = static_cast<int>(std::min<std::size_t>(budget / per_layer, 1u << 20));
  if (fit < 1) {
    throw GpuError("one z-layer of the SDF grid (" + std::to_string(spec.dims.x()) + " x " +
                   std::to_string(spec.dims.y()) + " voxels, " + std::to_string(per_layer >> 20) +
                   " MiB) exceeds the slab memory budget; use a larger voxel size");
  }
  const int wanted = std::min(fit, spec.dims.z());
  // Whole draws per slab keep every draw's layers inside one slab.
  return wanted >= kLayersPerDraw ? wanted / kLayersPerDraw * kLayersPerDraw : wanted;
}

}  // namespace

std::size_t bytes_per_layer(const GridSpec& spec) {
  return static_cast<std::size_t>(spec.dims.x()) * static_cast<std::size_t>(spec.dims.y()) * (16 + 4);
}

ScanConvertResult scan_convert(gpu::Context& context, const TriangleMesh& mesh, const Pseudonormals& normals,
                               const GridSpec& spec, const ScanConvertOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (options.band < 1.0) throw InputError("SDF band half-width must be at least 1 voxel (got " + std::to_string(options.band) + ")");
  const int max_size = context.limits().max_3d_texture_size;
  if (spec.dims.x() > max_size || spec.dims.y() > max_size) {
    throw GpuError("SDF grid " + std::to_string(spec.dims.x()) + " x " + std::to_string(spec.dims.y()) +
                   " exceeds this GPU's largest render target side (" + std::to_string(max_size) + ")");
  }
  // Every voxel with |d| < band lies inside the triangle's prism grown by the band; a quarter voxel
  // more keeps rounding of the cross-sections (~1e-6 voxel) from losing one, and costs far fewer
  // fragments than a whole voxel ((4.25/5)^3 for tiny triangles). The fragment shader drops what
  // lies beyond depth_range.
  const double margin = options.band + 0.25;
  const GpuGeometry geometry = build_geometry(mesh, normals, spec, margin);
  const int slab_layers = choose_slab_layers(spec, options.max_slab_bytes);
  const int block = std::min(kLayersPerDraw, slab_layers);
  const DrawLists lists = bucket_by_block(geometry, spec.dims.z(), block);

  gpu::ShaderLibrary library;
  std::vector<gpu::Program> programs;
  for (int invocations : kVariantInvocations) {
    programs.push_back(gpu::Program::graphics(library, "sdf/scan_convert.vert", "sdf/scan_convert.geom",
                                              "sdf/scan_convert.frag", {"INVOCATIONS " + std::to_string(invocations)}));
  }
  std::vector<std::string> timer_names;
  for (int invocations : kVariantInvocations)
    timer_names.push_back(fmt::format("sdf/scan_convert ({} GS invocations)", invocations));
  gpu::Buffer triangles = gpu::Buffer::from<SdfTriangle>(geometry.triangles);
  gpu::Buffer prisms = gpu::Buffer::from<SdfPrism>(geometry.prisms);
  gpu::Buffer indices = gpu::Buffer::from<std::uint32_t>(lists.indices);
  triangles.bind(TS_BINDING_SDF_TRIANGLES);
  prisms.bind(TS_BINDING_SDF_PRISMS);
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  glVertexArrayElementBuffer(vao, indices.id());

  SlabTarget target(spec.dims.x(), spec.dims.y(), slab_layers);
  gpu::Queue queue(options.timings, context.debug());

  ScanConvertResult result;
  ScanConvertStats& stats = result.stats;
  stats.layers_per_slab = slab_layers;
  stats.degenerate_triangles = geometry.degenerate;
  stats.needle_triangles = geometry.needles;
  stats.peak_gpu_bytes = bytes_per_layer(spec) * static_cast<std::size_t>(slab_layers) + triangles.bytes() +
                         prisms.bytes() + indices.bytes();

  const float h = static_cast<float>(spec.voxel_size);
  const float band = static_cast<float>(options.band);
  if (options.build_grid) result.grid = make_level_set(spec, band);
  std::optional<openvdb::FloatGrid::Accessor> accessor;
  if (result.grid) accessor.emplace(result.grid->getAccessor());
  if (options.keep_dense) {
    result.dense.spec = spec;
    result.dense.values.assign(spec.voxel_count(), Eigen::Vector4f(0, 0, 0, kUntouched));
  }
  const bool keep_signs = options.keep_dense || options.keep_texture;
  std::vector<std::uint8_t> state;
  if (keep_signs) state.assign(spec.voxel_count(), kOffBand);
  if (options.keep_texture) {
    result.texture = SdfTexture(spec, max_size);
    stats.peak_gpu_bytes += result.texture.bytes();
  }

  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer());
  glViewport(0, 0, spec.dims.x(), spec.dims.y());
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  for (gpu::Program& program : programs) {
    program.use();
    program.set("grid_xy", static_cast<float>(spec.dims.x()), static_cast<float>(spec.dims.y()));
    program.set("slab_layers", slab_layers);
    program.set("depth_range", static_cast<float>(margin));
    program.set("draw_layers", block);
  }
  glBindVertexArray(vao);

  const std::size_t layer_voxels = static_cast<std::size_t>(spec.dims.x()) * static_cast<std::size_t>(spec.dims.y());
  std::vector<float> readback(layer_voxels * 4 * static_cast<std::size_t>(slab_layers));
  for (int z0 = 0; z0 < spec.dims.z(); z0 += slab_layers) {
    const int layers = std::min(slab_layers, spec.dims.z() - z0);
    const float clear_value[4] = {0.0f, 0.0f, 0.0f, kUntouched};
    const float clear_depth = 1.0f;
    glClearNamedFramebufferfv(target.framebuffer(), GL_COLOR, 0, clear_value);
    glClearNamedFramebufferfv(target.framebuffer(), GL_DEPTH, 0, &clear_depth);
    for (int first = 0; first < layers; first += block) {
      for (std::size_t variant = 0; variant < kVariants; ++variant) {
        const std::size_t list = kVariants * static_cast<std::size_t>((z0 + first) / block) + variant;
        const std::size_t begin = lists.begin[list], end = lists.begin[list + 1];
        if (begin == end) continue;
        gpu::Program& program = programs[variant];
        program.use();
        program.set("slab_first_z", z0);
        program.set("draw_first_layer", first);
        queue.timed(timer_names[variant], [&] {
          glDrawElements(GL_LINES_ADJACENCY, static_cast<GLsizei>(end - begin), GL_UNSIGNED_INT,
                         reinterpret_cast<const void*>(begin * sizeof(std::uint32_t)));
        });
        ++stats.draws;
      }
    }
    queue.timed("sdf/readback", [&] {
      glGetTextureSubImage(target.color(), 0, 0, 0, 0, spec.dims.x(), spec.dims.y(), layers, GL_RGBA, GL_FLOAT,
                           static_cast<GLsizei>(layer_voxels * 4 * static_cast<std::size_t>(layers) * sizeof(float)),
                           readback.data());
    });
    if (options.keep_texture) {
      queue.timed("sdf/copy to texture", [&] {
        glCopyImageSubData(target.color(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, result.texture.id(), GL_TEXTURE_3D, 0, 0,
                           0, z0, spec.dims.x(), spec.dims.y(), layers);
      });
    }
    if (context.debug()) gpu::check_gl("SDF scan conversion (shaders sdf/scan_convert.*)");
    for (int layer = 0; layer < layers; ++layer) {
      const int k = z0 + layer;
      for (int j = 0; j < spec.dims.y(); ++j) {
        for (int i = 0; i < spec.dims.x(); ++i) {
          const float* v = &readback[4 * (static_cast<std::size_t>(layer) * layer_voxels +
                                          static_cast<std::size_t>(j) * static_cast<std::size_t>(spec.dims.x()) +
                                          static_cast<std::size_t>(i))];
          if (!(std::abs(v[3]) < band)) continue;
          if (accessor) {
            accessor->setValue(openvdb::Coord(spec.index_offset.x() + i, spec.index_offset.y() + j,
                                              spec.index_offset.z() + k),
                               v[3] * h);
          }
          ++stats.band_voxels;
          if (keep_signs) state[spec.linear_index(i, j, k)] = kInBand;
          if (options.keep_dense) result.dense.values[spec.linear_index(i, j, k)] = {v[0], v[1], v[2], v[3] * h};
        }
      }
    }
    ++stats.slabs;
    if (options.progress) options.progress(static_cast<double>(z0 + layers) / spec.dims.z());
  }
  glBindVertexArray(0);
  glDeleteVertexArrays(1, &vao);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);

  // Voxels outside the band take +-band: a closed band separates the inside from the outside, so a
  // flood fill classifies the whole grid (OpenVDB's signedFloodFill for the level set; a fill from
  // the grid border for the dense copy and the texture).
  if (result.grid) openvdb::tools::signedFloodFill(result.grid->tree());
  if (keep_signs) flood_fill_outside(spec, state);
  if (options.keep_dense) fill_dense_off_band(result.dense, state, band * h);
  if (options.keep_texture) finish_texture(queue, library, result.texture, state, band, h, stats.peak_gpu_bytes);
  if (options.timings) stats.timing_report = queue.timing_report();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace ts::sdf
