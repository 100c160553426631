#include "sdf/scan_convert.h"

#include <fmt/format.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <memory>
#include <span>
#include <utility>

#include "core/error.h"
#include "core/log.h"
#include "gpu/gl.h"
#include "gpu/graphics.h"
#include "gpu/hash_grid.h"
#include "gpu/layouts.h"
#include "sdf/compute_scan.h"
#include "sdf/level_set_builder.h"
#include "sdf/prism_model.h"
#include "shaders/sdf/bindings.h"

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

// A layered render target of `layers` z-slices: RGBA32F value + 32F depth (|d|, for the depth test).
struct SlabTarget {
  SlabTarget(int width, int height, int layers)
      : color(gpu::Texture::create_2d_array(GL_RGBA32F, width, height, layers, "SDF slab values")),
        depth(gpu::Texture::create_2d_array(GL_DEPTH_COMPONENT32F, width, height, layers, "SDF slab depth")),
        framebuffer("SDF slab") {
    framebuffer.attach_color(0, color);
    framebuffer.attach_depth(depth);
    framebuffer.check_complete();
  }
  gpu::Texture color, depth;
  gpu::Framebuffer framebuffer;
};

openvdb::FloatGrid::Ptr make_level_set(const GridSpec& spec, float band, bool index_space) {
  if (!index_space && !(spec.voxel_size >= kMinVdbVoxelSize)) {
    throw InputError(
        fmt::format("voxel size {:.3g} is below the smallest OpenVDB can store (1.3e-5 world units); "
                    "scale the mesh to smaller units (e.g. --scale 1000 for millimetres)",
                    spec.voxel_size));
  }
  auto grid = openvdb::FloatGrid::create(band * static_cast<float>(spec.voxel_size));
  // An index-space grid (voxel size 1, values still in world units) holds any voxel size: the GPU
  // field reads it by index alone.
  grid->setTransform(openvdb::math::Transform::createLinearTransform(index_space ? 1.0 : spec.voxel_size));
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

// `max_items`: the most voxels one slab's band compaction (and its scan) takes: slab voxels are
// numbered in 32 bits, and one dispatch covers 256 per work group times the device's work-group
// count limits along x and y (gpu::Queue::dispatch_groups lays the groups out in rows).
// `per_layer`: the GPU bytes one layer of the slab costs.
int choose_slab_layers(const GridSpec& spec, std::size_t per_layer, std::size_t budget, std::size_t max_items,
                       int max_layers) {
  const std::size_t layer_voxels = static_cast<std::size_t>(spec.dims.x()) * static_cast<std::size_t>(spec.dims.y());
  if (layer_voxels > max_items) {
    throw GpuError(fmt::format("one z-layer of the SDF grid ({} x {} voxels) exceeds the {} voxels one slab's band "
                               "compaction covers on this GPU; use a larger voxel size",
                               spec.dims.x(), spec.dims.y(), max_items));
  }
  const int fit = static_cast<int>(std::min<std::size_t>(
      {budget / per_layer, max_items / layer_voxels, static_cast<std::size_t>(std::max(max_layers, 1))}));
  if (fit < 1) {
    throw GpuError("one z-layer of the SDF grid (" + std::to_string(spec.dims.x()) + " x " +
                   std::to_string(spec.dims.y()) + " voxels, " + std::to_string(per_layer >> 20) +
                   " MiB) exceeds the slab memory budget; use a larger voxel size");
  }
  const int wanted = std::min(fit, spec.dims.z());
  // Whole draws per slab keep every draw's layers inside one slab.
  return wanted >= kLayersPerDraw ? wanted / kLayersPerDraw * kLayersPerDraw : wanted;
}

// The GPU field builds whole leaf rows per slab (sdf/leaf_field.h): slabs of a multiple of 8 layers,
// unless one slab holds the grid.
int whole_leaf_rows(int layers, int dims_z) {
  if (layers >= dims_z) return layers;
  if (layers < kLeafSide) {
    throw GpuError(fmt::format("the GPU field needs slabs of at least {} z-layers and this GPU holds {}; use a "
                               "larger voxel size", kLeafSide, layers));
  }
  return layers / kLeafSide * kLeafSide;
}

// Everything the slab loop needs that the CPU decides before the GPU is touched.
struct ScanPlan {
  ScanMethod method = ScanMethod::Geometry;
  double band = 0.0;    // half-width [voxels]
  double margin = 0.0;  // prism growth beyond the triangle [voxels]
  int slab_layers = 0;  // z-layers per slab (render-target layers)
  int block = 0;        // z-layers per draw
  GpuGeometry geometry;
  DrawLists lists;  // geometry path
  int brick = 0;    // compute path: the side of a brick [voxels] (its pairs are made on the GPU)
};

// `brick`: the compute path's brick side (compute_brick_side).
ScanPlan plan_scan(std::size_t max_items, int max_layers, int brick, const TriangleMesh& mesh,
                   const Pseudonormals& normals, const GridSpec& spec, const ScanConvertOptions& options) {
  ScanPlan plan;
  // Every voxel with |d| < band lies inside the triangle's prism grown by the band; a quarter voxel
  // more keeps rounding of the cross-sections (~1e-6 voxel) from losing one, and costs far fewer
  // fragments than a whole voxel ((4.25/5)^3 for tiny triangles). The fragment shader drops what
  // lies beyond depth_range.
  plan.method = options.method;
  plan.band = options.band;
  plan.margin = options.band + 0.25;
  plan.geometry = build_geometry(mesh, normals, spec, plan.margin);
  const bool compute = options.method == ScanMethod::Compute;
  const std::size_t per_layer =
      bytes_per_layer(spec) + (compute ? kComputeScanBytesPerVoxel * static_cast<std::size_t>(spec.dims.x()) *
                                             static_cast<std::size_t>(spec.dims.y())
                                       : 0);
  plan.slab_layers = choose_slab_layers(spec, per_layer, options.max_slab_bytes, max_items, max_layers);
  if (options.gpu_field) plan.slab_layers = whole_leaf_rows(plan.slab_layers, spec.dims.z());
  plan.block = std::min(kLayersPerDraw, plan.slab_layers);
  plan.brick = brick;
  if (!compute) plan.lists = bucket_by_block(plan.geometry, spec.dims.z(), plan.block);
  return plan;
}

// The GPU half of scan conversion: both geometry-shader variants, the geometry buffers, the indexed
// vertex array and the layered target, bound (with the depth test on |d|) while it exists. Draws
// one slab at a time and reads it back.
class SlabScanner {
 public:
  SlabScanner(const gpu::ShaderLibrary& library, gpu::Queue& queue, const GridSpec& spec,
              const ScanPlan& plan);
  // Clears the target and draws every prism touching grid layers [z0, z0 + layers) (or, on the
  // compute path, runs the triangle/brick pairs of those layers); returns the number of draws (or 0).
  int draw(int z0, int layers);
  // The band voxels of the target's first `layers` layers, compacted on the GPU and read back: their
  // slab indices (x fastest, then y, then layer; ascending) and 4 floats each (unit gradient,
  // signed distance [voxels]). Only the band crosses to the host.
  struct Band {
    std::span<const std::size_t> indices;
    std::span<const float> values;
  };
  Band read_band(int layers, float band);
  // Render target, geometry and compaction buffers [bytes] (the largest they have been).
  std::size_t gpu_bytes() const {
    return bytes_per_layer(spec_) * static_cast<std::size_t>(plan_.slab_layers) + triangles_.bytes() +
           prisms_.bytes() + indices_.bytes() + flags_.bytes() + band_indices_.bytes() +
           band_values_.bytes() + (compute_ ? compute_->gpu_bytes() : 0);
  }
  std::size_t brick_pairs_run() const { return brick_pairs_run_; }  // compute path, over all slabs
  // Geometry path: starts counting the raster pipeline's work (gpu::PipelineStatistics) from the next slab.
  void count_pipeline() { pipeline_ = std::make_unique<gpu::PipelineStatistics>(); }
  // What was counted, with the invocations the draws asked for; measured false when nothing was.
  ScanPipelineWork pipeline_work() const;
  std::size_t readback_bytes() const { return readback_bytes_; }  // field bytes read back so far
  const gpu::Texture& slab() const { return target_.color; }       // the filled slab (after draw)

 private:
  const GridSpec& spec_;
  const ScanPlan& plan_;
  gpu::Queue& queue_;
  std::vector<gpu::Program> programs_;  // one per kVariantInvocations
  std::vector<std::string> timer_names_;
  gpu::ParamArray<gpu::params::ScanConvertParams> draw_params_;  // one entry per draw of a slab
  gpu::Buffer triangles_, prisms_, indices_;
  gpu::VertexArray vertices_;
  SlabTarget target_;
  // Band compaction: flags (scanned in place into offsets), the compacted band, its host copy.
  gpu::Program flag_band_, scatter_band_;
  gpu::ParamBlock<gpu::params::BandParams> band_params_;
  gpu::PrefixScan scan_;
  gpu::Buffer flags_, band_indices_, band_values_;
  std::vector<std::uint32_t> index_words_;
  std::vector<std::size_t> band_slab_indices_;
  std::vector<float> band_values_host_;
  std::size_t readback_bytes_ = 0;
  std::unique_ptr<ComputeScan> compute_;  // the compute path's kernels and buffers; null on the geometry path
  std::size_t brick_pairs_run_ = 0;
  std::unique_ptr<gpu::PipelineStatistics> pipeline_;  // null unless count_pipeline()
  std::uint64_t drawn_prisms_ = 0;                     // sum over draws of the prisms drawn
  std::uint64_t model_invocations_ = 0;                // sum over draws of prisms x variant invocations
  gpu::StateScope state_;  // last: restores the state before the target is released
};

SlabScanner::SlabScanner(const gpu::ShaderLibrary& library, gpu::Queue& queue, const GridSpec& spec,
                         const ScanPlan& plan)
    : spec_(spec),
      plan_(plan),
      queue_(queue),
      triangles_(gpu::Buffer::from<SdfTriangle>(plan.geometry.triangles)),
      prisms_(gpu::Buffer::from<SdfPrism>(plan.geometry.prisms)),
      indices_(gpu::Buffer::from<std::uint32_t>(plan.lists.indices)),
      vertices_(gpu::VertexArray::create()),
      target_(spec.dims.x(), spec.dims.y(), plan.slab_layers),
      flag_band_(gpu::Program::compute(library, "sdf/band_flags.comp")),
      scatter_band_(gpu::Program::compute(library, "sdf/band_scatter.comp")),
      scan_(library),
      flags_(static_cast<std::size_t>(spec.dims.x()) * static_cast<std::size_t>(spec.dims.y()) *
             static_cast<std::size_t>(plan.slab_layers) * sizeof(std::uint32_t)) {
  target_.color.set_sampling(GL_NEAREST);  // read by texelFetch; a complete texture needs a non-mip filter
  if (plan.method == ScanMethod::Compute) {
    // The same margin as the prisms: the pairs reach every voxel a prism would.
    BrickPairGenerator generator(library);
    GpuBrickPairs pairs;
    queue.timed("sdf/brick_pairs", [&] {
      pairs = generator.run(queue, triangles_, static_cast<std::uint32_t>(plan.geometry.triangles.size()), spec,
                            plan.margin, plan.brick);
    });
    compute_ = std::make_unique<ComputeScan>(library, std::move(pairs), spec, plan.slab_layers, plan.band);
  }
  // The compute path draws nothing: no geometry-shader programs to compile.
  for (int invocations : compute_ ? std::span<const int>{} : std::span<const int>{kVariantInvocations}) {
    programs_.push_back(gpu::Program::graphics(library, "sdf/scan_convert.vert", "sdf/scan_convert.geom",
                                               "sdf/scan_convert.frag",
                                               {"INVOCATIONS " + std::to_string(invocations)}));
    timer_names_.push_back(fmt::format("sdf/scan_convert ({} GS invocations)", invocations));
  }
  vertices_.set_element_buffer(indices_);
  state_.framebuffer(target_.framebuffer).viewport(spec.dims.x(), spec.dims.y()).vertex_array(vertices_);
  state_.depth_test(GL_LESS).no_cull().no_blend();
}

int SlabScanner::draw(int z0, int layers) {
  // Rebound every slab: the band compaction of the last slab used the same slot numbers.
  triangles_.bind(TS_SDF_TRIANGLES);
  prisms_.bind(TS_SDF_PRISMS);
  target_.framebuffer.clear_color(0, {0.0f, 0.0f, 0.0f, kUntouched});
  target_.framebuffer.clear_depth(1.0f);
  if (compute_) {
    brick_pairs_run_ += compute_->fill(queue_, triangles_, target_.color, z0, layers);
    return 0;
  }
  struct Draw {
    std::size_t variant, begin, count;
  };
  std::vector<Draw> draws;
  std::vector<gpu::params::ScanConvertParams> params;
  for (int first = 0; first < layers; first += plan_.block) {
    for (std::size_t variant = 0; variant < kVariants; ++variant) {
      const std::size_t list = kVariants * static_cast<std::size_t>((z0 + first) / plan_.block) + variant;
      const std::size_t begin = plan_.lists.begin[list], end = plan_.lists.begin[list + 1];
      if (begin == end) continue;
      draws.push_back({variant, begin, end - begin});
      params.push_back({{z0, layers, first, plan_.block},
                        {static_cast<float>(spec_.dims.x()), static_cast<float>(spec_.dims.y()),
                         static_cast<float>(plan_.margin), 0.0f}});
    }
  }
  // The slab's parameters go up in one upload, before its first draw (gpu::ParamArray says why).
  draw_params_.upload(params);
  if (pipeline_) pipeline_->begin();
  for (std::size_t d = 0; d < draws.size(); ++d) {
    draw_params_.bind(d, TS_SDF_SCAN_PARAMS);
    gpu::draw_elements(queue_, programs_[draws[d].variant], GL_LINES_ADJACENCY, draws[d].begin, draws[d].count,
                       timer_names_[draws[d].variant]);
    drawn_prisms_ += draws[d].count / 4;
    model_invocations_ += draws[d].count / 4 * static_cast<std::uint64_t>(kVariantInvocations[draws[d].variant]);
  }
  if (pipeline_) pipeline_->end();
  return static_cast<int>(draws.size());
}

ScanPipelineWork SlabScanner::pipeline_work() const {
  ScanPipelineWork work;
  if (!pipeline_) return work;
  const gpu::PipelineCounts& counts = pipeline_->counts();
  work.measured = true;
  work.geometry_invocations = counts.geometry_invocations;
  work.geometry_primitives = counts.geometry_primitives;
  work.fragments = counts.fragment_invocations;
  work.drawn_prisms = drawn_prisms_;
  work.model_invocations = model_invocations_;
  const PrismWorkModel model = model_prism_work(plan_.geometry.prisms, plan_.geometry.drawn, spec_.dims.z());
  work.model_primitives = model.primitives;
  work.model_volume = model.volume;
  return work;
}

SlabScanner::Band SlabScanner::read_band(int layers, float band) {
  const std::uint32_t voxels = static_cast<std::uint32_t>(spec_.dims.x()) * static_cast<std::uint32_t>(spec_.dims.y()) *
                               static_cast<std::uint32_t>(layers);
  band_params_.values = {{spec_.dims.x(), spec_.dims.y(), 0, 0}, {voxels, 0u, 0u, 0u}, {band, 0.0f, 0.0f, 0.0f}};
  band_params_.bind(TS_SDF_BAND_PARAMS);
  target_.color.bind_unit(TS_SDF_UNIT_SLAB);
  flags_.bind(TS_SDF_BAND_FLAGS);
  // Host reads of what a kernel wrote need the buffer-update barrier besides the storage one.
  constexpr GLbitfield kToHost = GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT;
  queue_.dispatch_items(flag_band_, voxels, kToHost);
  // The last flag, read before the scan overwrites it, plus the last offset: the band's size.
  const std::uint32_t last_flag = flags_.read<std::uint32_t>(1, voxels - 1)[0];
  scan_.run(queue_, flags_, voxels);
  const std::size_t count = flags_.read<std::uint32_t>(1, voxels - 1)[0] + last_flag;
  if (band_indices_.bytes() < count * sizeof(std::uint32_t)) {
    band_indices_ = gpu::Buffer(std::max<std::size_t>(count, 1) * sizeof(std::uint32_t));
    band_values_ = gpu::Buffer(std::max<std::size_t>(count, 1) * 4 * sizeof(float));
  }
  flags_.bind(TS_SDF_BAND_OFFSETS);
  band_indices_.bind(TS_SDF_BAND_INDICES);
  band_values_.bind(TS_SDF_BAND_VALUES);
  band_params_.bind(TS_SDF_BAND_PARAMS);  // again: the scan's own parameters took the slot
  queue_.dispatch_items(scatter_band_, voxels, kToHost);
  gpu::Texture::unbind_unit(TS_SDF_UNIT_SLAB);
  index_words_.resize(count);
  band_values_host_.resize(4 * count);
  queue_.timed("sdf/readback", [&] {
    if (count == 0) return;
    band_indices_.download(index_words_.data(), count * sizeof(std::uint32_t));
    band_values_.download(band_values_host_.data(), count * 4 * sizeof(float));
  });
  // Field bytes only: the two counts read above are not the field.
  readback_bytes_ += count * (sizeof(std::uint32_t) + 4 * sizeof(float));
  band_slab_indices_.assign(index_words_.begin(), index_words_.end());
  return {band_slab_indices_, band_values_host_};
}

// A finished slab: grid layers [z0, z0 + layers), of which only the band was read back.
struct Slab {
  const GridSpec& spec;
  int z0 = 0, layers = 0;
  std::span<const std::size_t> band;  // the voxels with |distance| < band, ascending slab order
  std::span<const float> values;      // 4 per band voxel: unit gradient, signed distance [voxels]

  std::size_t layer_voxels() const {
    return static_cast<std::size_t>(spec.dims.x()) * static_cast<std::size_t>(spec.dims.y());
  }
  // Slab order is grid order (x fastest, then y, then z) from layer z0 on.
  std::size_t grid_index(std::size_t voxel) const {
    return static_cast<std::size_t>(z0) * layer_voxels() + voxel;
  }
};

// One output of scan conversion: fed every finished slab in z order, then finished once.
class SlabConsumer {
 public:
  virtual ~SlabConsumer() = default;
  virtual void consume(const Slab& slab) = 0;
  virtual void finish() = 0;
  // Work done on other threads (beside the GPU's) [s].
  virtual double background_seconds() const { return 0.0; }
};

// The OpenVDB level set: band voxels in world units, then a signed flood fill for the rest. Leaves
// are built in parallel, each slab's while the GPU scans the next (sdf/level_set_builder.h).
class LevelSetOutput final : public SlabConsumer {
 public:
  LevelSetOutput(const GridSpec& spec, float band, bool index_space, openvdb::FloatGrid::Ptr& grid)
      : grid_(grid = make_level_set(spec, band, index_space)),
        builder_(grid_->tree(), spec, static_cast<float>(spec.voxel_size)) {}
  void consume(const Slab& slab) override { builder_.add({slab.z0, slab.band, slab.values}); }
  void finish() override {
    builder_.finish();
    openvdb::tools::signedFloodFill(grid_->tree());
  }
  double background_seconds() const override { return builder_.build_seconds(); }

 private:
  openvdb::FloatGrid::Ptr grid_;
  LevelSetBuilder builder_;
};

// Which voxels the band holds and, after the last slab, which of the others lie outside: the signs
// off the band for the dense copy.
class BandSigns final : public SlabConsumer {
 public:
  explicit BandSigns(const GridSpec& spec) : spec_(spec), state_(spec.voxel_count(), kOffBand) {}
  void consume(const Slab& slab) override {
    for (std::size_t voxel : slab.band) state_[slab.grid_index(voxel)] = kInBand;
  }
  void finish() override { flood_fill_outside(spec_, state_); }
  const std::vector<std::uint8_t>& state() const { return state_; }

 private:
  const GridSpec& spec_;
  std::vector<std::uint8_t> state_;  // VoxelState per voxel, spec.linear_index order
};

// The dense host copy: band voxels as read back (distance in world units), the rest +-band.
class DenseOutput final : public SlabConsumer {
 public:
  DenseOutput(const GridSpec& spec, float band, const BandSigns& signs, DenseSdf& dense)
      : voxel_size_(static_cast<float>(spec.voxel_size)), band_(band), signs_(signs), dense_(dense) {
    dense_.spec = spec;
    dense_.values.assign(spec.voxel_count(), Eigen::Vector4f(0, 0, 0, kUntouched));
  }
  void consume(const Slab& slab) override {
    for (std::size_t k = 0; k < slab.band.size(); ++k) {
      const float* v = &slab.values[4 * k];
      dense_.values[slab.grid_index(slab.band[k])] = {v[0], v[1], v[2], v[3] * voxel_size_};
    }
  }
  void finish() override { fill_dense_off_band(dense_, signs_.state(), band_ * voxel_size_); }

 private:
  float voxel_size_, band_;
  const BandSigns& signs_;
  DenseSdf& dense_;
};

// The outputs the options choose, in the order they finish (the signs before the dense copy that
// reads them).
std::vector<std::unique_ptr<SlabConsumer>> make_outputs(const GridSpec& spec, const ScanConvertOptions& options,
                                                        ScanConvertResult& result) {
  const float band = static_cast<float>(options.band);
  std::vector<std::unique_ptr<SlabConsumer>> outputs;
  if (options.build_grid) {
    outputs.push_back(std::make_unique<LevelSetOutput>(spec, band, options.index_space_grid, result.grid));
  }
  if (!options.keep_dense) return outputs;
  auto signs = std::make_unique<BandSigns>(spec);
  const BandSigns& shared_signs = *signs;
  outputs.push_back(std::move(signs));
  outputs.push_back(std::make_unique<DenseOutput>(spec, band, shared_signs, result.dense));
  return outputs;
}

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Draws, reads back and hands on each slab in z order. stats.gpu_seconds gets the time spent
// drawing and reading back (the read-back is split off by the caller), stats.host_build_seconds the
// time spent handing slabs on.
// `leaves`, when not null, builds the GPU field from each slab on the GPU; the band is read back only
// for the host outputs.
void scan_slabs(SlabScanner& scanner, const std::vector<std::unique_ptr<SlabConsumer>>& outputs,
                LeafFieldBuilder* leaves, const GridSpec& spec, const ScanConvertOptions& options,
                bool check_errors, ScanConvertStats& stats) {
  const float band = static_cast<float>(options.band);
  for (int z0 = 0; z0 < spec.dims.z(); z0 += stats.layers_per_slab) {
    const int layers = std::min(stats.layers_per_slab, spec.dims.z() - z0);
    auto lap = Clock::now();
    stats.draws += scanner.draw(z0, layers);
    if (leaves) leaves->add_slab(scanner.slab(), z0, layers);
    if (!outputs.empty()) {
      const SlabScanner::Band voxels = scanner.read_band(layers, band);
      stats.gpu_seconds += seconds_since(lap);
      lap = Clock::now();
      const Slab slab{spec, z0, layers, voxels.indices, voxels.values};
      for (const auto& output : outputs) output->consume(slab);
      stats.host_build_seconds += seconds_since(lap);
      stats.band_voxels += voxels.indices.size();
    } else {
      stats.gpu_seconds += seconds_since(lap);
    }
    if (check_errors) gpu::check_gl("SDF scan conversion (shaders sdf/scan_*, sdf/band_*.comp, sdf/leaf_*.comp)");
    ++stats.slabs;
    if (options.progress) options.progress(static_cast<double>(z0 + layers) / spec.dims.z());
  }
}

void check_request(const gpu::Context& context, const GridSpec& spec, const ScanConvertOptions& options) {
  if (options.band < 1.0) {
    throw InputError("SDF band half-width must be at least 1 voxel (got " + std::to_string(options.band) +
                     ")");
  }
  // The slab is a layered 2D array target, so its side is bounded by 2D textures, framebuffers and the
  // viewport, not by 3D textures (2048 on llvmpipe, where 2D goes to 16384).
  const gpu::DeviceLimits& l = context.limits();
  const int max_x = std::min({l.max_texture_size, l.max_framebuffer_size[0], l.max_viewport_dims[0]});
  const int max_y = std::min({l.max_texture_size, l.max_framebuffer_size[1], l.max_viewport_dims[1]});
  if (spec.dims.x() > max_x || spec.dims.y() > max_y) {
    throw GpuError(fmt::format("SDF grid {} x {} (x by y) exceeds this GPU's largest layered render target ({} x {}); "
                               "use a larger voxel",
                               spec.dims.x(), spec.dims.y(), max_x, max_y));
  }
}

// Layers one slab target may have: 2D array layers and layered-framebuffer layers.
std::size_t max_slab_items(const gpu::Context& context) {
  const gpu::DeviceLimits& l = context.limits();
  const std::size_t groups = static_cast<std::size_t>(l.max_compute_work_group_count[0]) *
                             static_cast<std::size_t>(std::max(l.max_compute_work_group_count[1], 1));
  return std::min<std::size_t>(std::numeric_limits<std::uint32_t>::max(), 256u * groups);
}

int max_slab_layers(const gpu::Context& context) {
  const gpu::DeviceLimits& l = context.limits();
  return std::min(l.max_texture_layers, l.max_framebuffer_layers > 0 ? l.max_framebuffer_layers : l.max_texture_layers);
}

}  // namespace

std::size_t bytes_per_layer(const GridSpec& spec) {
  return static_cast<std::size_t>(spec.dims.x()) * static_cast<std::size_t>(spec.dims.y()) * (16 + 4);
}

ScanConvertResult scan_convert(gpu::Context& context, const TriangleMesh& mesh, const Pseudonormals& normals,
                               const GridSpec& spec, const ScanConvertOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_request(context, spec, options);
  const ScanPlan plan = plan_scan(max_slab_items(context), max_slab_layers(context),
                                  options.compute_brick > 0 ? options.compute_brick
                                                            : compute_brick_side(context.software()),
                                  mesh, normals, spec, options);
  gpu::ShaderLibrary library;
  gpu::Queue queue(options.timings, context.debug());
  SlabScanner scanner(library, queue, spec, plan);
  if (options.pipeline_statistics && plan.method == ScanMethod::Geometry && gpu::PipelineStatistics::available())
    scanner.count_pipeline();

  ScanConvertResult result;
  ScanConvertStats& stats = result.stats;
  stats.method = plan.method;
  stats.layers_per_slab = plan.slab_layers;
  stats.degenerate_triangles = plan.geometry.degenerate;
  stats.needle_triangles = plan.geometry.needles;
  const auto outputs = make_outputs(spec, options, result);
  std::optional<LeafFieldBuilder> leaves;
  if (options.gpu_field) {
    result.field.emplace(spec, options.band,
                         options.gpu_field_slots > 0 ? options.gpu_field_slots
                                                     : band_leaf_bound(mesh, spec, options.band));
    leaves.emplace(library, queue, *result.field);
  }
  scan_slabs(scanner, outputs, leaves ? &*leaves : nullptr, spec, options, queue.checks_errors(), stats);
  stats.peak_gpu_bytes = scanner.gpu_bytes() + (leaves ? leaves->gpu_bytes() + result.field->gpu_bytes() : 0);
  if (leaves) {
    const auto finishing = Clock::now();
    leaves->finish();
    stats.gpu_seconds += seconds_since(finishing);
    if (outputs.empty()) stats.band_voxels = result.field->band_voxels();
  }
  stats.readback_bytes = scanner.readback_bytes();
  stats.brick_pairs = scanner.brick_pairs_run();
  stats.pipeline = scanner.pipeline_work();
  // Voxels outside the band take +-band: a closed band separates the inside from the outside, so a
  // flood fill classifies the whole grid (OpenVDB's signedFloodFill for the level set; a fill from
  // the grid border for the dense copy).
  const auto finishing = Clock::now();
  for (const auto& output : outputs) output->finish();
  stats.host_build_seconds += seconds_since(finishing);
  // The band's download, timed by the host inside read_band, is the read-back; the rest of the time
  // the scanner took is the GPU's (draws and compaction, the host waiting on them).
  stats.readback_seconds = std::min(queue.host_seconds("sdf/readback"), stats.gpu_seconds);
  stats.gpu_seconds -= stats.readback_seconds;
  for (const auto& output : outputs) stats.leaf_build_seconds += output->background_seconds();
  if (options.timings) stats.timing_report = queue.timing_report();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace ts::sdf
