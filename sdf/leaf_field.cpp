#include "sdf/leaf_field.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "core/error.h"
#include "shaders/common/layouts.h"
#include "shaders/sdf/bindings.h"

namespace ts::sdf {
namespace {

// What the scan adds to the band around each triangle (sdf/scan_convert.cpp, plan_scan's margin).
constexpr double kScanMargin = 0.25;

// Marks the leaf cells near triangle `v` (grid-local voxel units) in `marked`; returns how many it newly marked.
std::size_t mark_triangle_cells(const Eigen::Vector3d (&v)[3], const Eigen::Vector3i& cells, double reach,
                                std::vector<std::uint8_t>& marked) {
  const Eigen::Vector3d lo = v[0].cwiseMin(v[1]).cwiseMin(v[2]).array() - reach;
  const Eigen::Vector3d hi = v[0].cwiseMax(v[1]).cwiseMax(v[2]).array() + reach;
  Eigen::Vector3i first, last;
  for (int a = 0; a < 3; ++a) {
    // Cell c holds voxel centres 8c .. 8c + 7.
    first[a] = std::clamp(static_cast<int>(std::floor(lo[a] / kLeafSide)), 0, cells[a] - 1);
    last[a] = std::clamp(static_cast<int>(std::floor(hi[a] / kLeafSide)), 0, cells[a] - 1);
    if (hi[a] < 0.0 || lo[a] > static_cast<double>(cells[a]) * kLeafSide) return 0;
  }
  const Eigen::Vector3d cross = (v[1] - v[0]).cross(v[2] - v[0]);
  const double area2 = cross.norm();
  // A degenerate triangle gets its box alone: no plane to test against.
  const Eigen::Vector3d n = area2 > 0.0 ? Eigen::Vector3d(cross / area2) : Eigen::Vector3d::Zero();
  const double half_extent = 0.5 * (kLeafSide - 1) * n.cwiseAbs().sum();  // of a cell's voxel centres along n
  std::size_t added = 0;
  for (int z = first.z(); z <= last.z(); ++z)
    for (int y = first.y(); y <= last.y(); ++y)
      for (int x = first.x(); x <= last.x(); ++x) {
        const Eigen::Vector3d centre = Eigen::Vector3d(x, y, z) * kLeafSide + Eigen::Vector3d::Constant(3.5);
        if (area2 > 0.0 && std::abs(n.dot(centre - v[0])) - half_extent > reach) continue;
        std::uint8_t& m = marked[(static_cast<std::size_t>(z) * cells.y() + y) * cells.x() + x];
        added += m == 0;
        m = 1;
      }
  return added;
}

GLint64 max_storage_block() {
  GLint64 bytes = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &bytes);
  return bytes;
}

}  // namespace

Eigen::Vector3i leaf_cells(const GridSpec& spec) {
  return (spec.dims.array() + (kLeafSide - 1)) / kLeafSide;
}

std::size_t band_leaf_bound(const TriangleMesh& mesh, const GridSpec& spec, double band) {
  const Eigen::Vector3i cells = leaf_cells(spec);
  std::vector<std::uint8_t> marked(static_cast<std::size_t>(cells.x()) * cells.y() * cells.z(), 0);
  // A little over the scan's own margin: the bound must hold whatever the rounding.
  const double reach = band + kScanMargin + 0.25;
  std::size_t count = 0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    Eigen::Vector3d v[3];
    for (int k = 0; k < 3; ++k) v[k] = spec.to_voxel(mesh.vertices[mesh.triangles[t][k]]);
    count += mark_triangle_cells(v, cells, reach, marked);
  }
  return count;
}

std::size_t leaf_field_bytes(const GridSpec& spec, std::size_t slots) {
  const Eigen::Vector3i cells = leaf_cells(spec);
  return static_cast<std::size_t>(cells.x()) * cells.y() * cells.z() * sizeof(std::uint32_t) +
         std::max<std::size_t>(slots, 1) * kLeafBytes;
}

std::size_t gpu_field_memory_limit() {
  if (const char* cap = std::getenv("TETRASAND_GPU_MEMORY_MIB"); cap && *cap) {
    char* end = nullptr;
    const double mib = std::strtod(cap, &end);
    if (end == cap || *end != '\0' || !(mib > 0.0) || !std::isfinite(mib)) {
      throw InputError(fmt::format("TETRASAND_GPU_MEMORY_MIB must be a positive number of MiB (got '{}')", cap));
    }
    return static_cast<std::size_t>(mib * 1048576.0);
  }
  if (glewIsSupported("GL_NVX_gpu_memory_info")) {
    GLint kib = 0;
    glGetIntegerv(0x9049 /* GL_GPU_MEMORY_INFO_CURRENT_AVAILABLE_VIDMEM_NVX */, &kib);
    glGetError();
    if (kib > 0) return static_cast<std::size_t>(kib) * 1024;
  }
  return 0;
}

LeafField::LeafField(const GridSpec& spec, double band_voxels, std::size_t slots)
    : spec_(spec),
      band_(band_voxels),
      // The host level set's background, float times float (sdf/scan_convert.cpp, make_level_set), so
      // both fields hold the same bits off the band.
      background_(static_cast<float>(band_voxels) * static_cast<float>(spec.voxel_size)),
      slots_(std::max<std::size_t>(slots, 1)) {
  const std::size_t bytes = slots_ * kLeafBytes;
  const GLint64 block = max_storage_block();
  if (slots_ > kMaxLeafSlots || static_cast<GLint64>(bytes) > block) {
    throw GpuError(fmt::format("the GPU field's {} leaves ({:.1f} MiB) exceed this GPU's largest storage block "
                               "({:.1f} MiB) or {} leaves; use a larger voxel",
                               slots_, bytes / 1048576.0, static_cast<double>(block) / 1048576.0, kMaxLeafSlots));
  }
  const Eigen::Vector3i c = cells();
  index_ = gpu::Buffer(static_cast<std::size_t>(c.x()) * c.y() * c.z() * sizeof(std::uint32_t));
  values_ = gpu::Buffer(bytes);
}

void LeafField::bind(const FieldSlots& slots) const {
  values_.bind(slots.first);
  index_.bind(slots.roots);
  const Eigen::Vector3i c = cells();
  params_.values.index_offset = {0, 0, 0, 0};
  params_.values.scale = {static_cast<float>(spec_.voxel_size), background_, 0.0f, 0.0f};
  params_.values.root_first = {c.x(), c.y(), c.z(), 0};
  params_.values.roots = {0u, 0u, 0u, 0u};
  params_.bind(slots.params);
}

LeafField::HostCopy LeafField::download() const {
  const Eigen::Vector3i c = cells();
  HostCopy copy;
  copy.index = index_.read<std::uint32_t>(static_cast<std::size_t>(c.x()) * c.y() * c.z());
  copy.values = values_.read<float>(band_leaves_ * kLeafVoxels);
  return copy;
}

LeafFieldBuilder::LeafFieldBuilder(const gpu::ShaderLibrary& library, gpu::Queue& queue, LeafField& field)
    : field_(field),
      queue_(queue),
      flag_(gpu::Program::compute(library, "sdf/leaf_flags.comp")),
      assign_(gpu::Program::compute(library, "sdf/leaf_assign.comp")),
      fill_(gpu::Program::compute(library, "sdf/leaf_fill.comp")),
      signs_(gpu::Program::compute(library, "sdf/leaf_signs.comp")),
      scan_(library),
      counts_(4 * sizeof(std::uint32_t)) {
  counts_.fill_zero();
  const Eigen::Vector3i c = field.cells();
  const GridSpec& spec = field.spec();
  params_.values.grid = {spec.dims.x(), spec.dims.y(), spec.dims.z(), 0};
  params_.values.leaves = {c.x(), c.y(), c.z(), 0};
  params_.values.cells = {0u, 0u, static_cast<std::uint32_t>(field.slots()), 0u};
  params_.values.band = {static_cast<float>(field.band()), static_cast<float>(spec.voxel_size), field.background(),
                         0.0f};
}

void LeafFieldBuilder::dispatch(const gpu::Program& program, std::size_t items, GLbitfield barrier) {
  params_.bind(TS_SDF_LEAF_PARAMS);  // again each time: the scan's own parameters may take the slot
  field_.index_.bind(TS_SDF_LEAF_INDEX);
  flags_.bind(TS_SDF_LEAF_FLAGS);
  field_.values_.bind(TS_SDF_LEAF_VALUES);
  counts_.bind(TS_SDF_LEAF_COUNTS);
  queue_.dispatch_items(program, items, barrier);
}

void LeafFieldBuilder::add_slab(const gpu::Texture& slab, int z0, int layers) {
  if (z0 % kLeafSide != 0) {
    throw Error(ExitCode::Internal, fmt::format("LeafFieldBuilder: a slab starts at layer {}, not a leaf row", z0));
  }
  const Eigen::Vector3i c = field_.cells();
  const std::uint32_t rows = static_cast<std::uint32_t>((layers + kLeafSide - 1) / kLeafSide);
  const std::uint32_t per_row = static_cast<std::uint32_t>(c.x()) * static_cast<std::uint32_t>(c.y());
  const std::uint32_t cells = per_row * rows;
  if (flags_.bytes() < cells * sizeof(std::uint32_t)) flags_ = gpu::Buffer(cells * sizeof(std::uint32_t));
  params_.values.grid.w = z0;
  params_.values.leaves.w = static_cast<int>(rows);
  params_.values.cells.x = cells;
  params_.values.cells.y = per_row * static_cast<std::uint32_t>(z0 / kLeafSide);
  params_.values.cells.w = static_cast<std::uint32_t>(slabs_ % 2);
  slab.bind_unit(TS_SDF_UNIT_SLAB);
  dispatch(flag_, cells);
  scan_.run(queue_, flags_, cells);
  dispatch(assign_, cells);
  dispatch(fill_, cells);
  gpu::Texture::unbind_unit(TS_SDF_UNIT_SLAB);
  ++slabs_;
}

void LeafFieldBuilder::finish() {
  const Eigen::Vector3i c = field_.cells();
  // Host reads of what a kernel wrote need the buffer-update barrier besides the storage one.
  dispatch(signs_, static_cast<std::size_t>(c.x()) * static_cast<std::size_t>(c.y()),
           GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  const std::vector<std::uint32_t> counts = counts_.read<std::uint32_t>(4);
  if (counts[3] != 0) {
    throw Error(ExitCode::Internal, fmt::format("the GPU field's band leaves outgrew the {} slots their bound gave",
                                                field_.slots()));
  }
  field_.band_leaves_ = counts[static_cast<std::size_t>(slabs_ % 2)];
  field_.band_voxels_ = counts[2];
}

}  // namespace ts::sdf
