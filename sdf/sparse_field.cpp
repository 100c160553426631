#include "sdf/sparse_field.h"

#include <fmt/format.h>

#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"

namespace ts::sdf {

NanoGrid to_nanovdb(const openvdb::FloatGrid& level_set) {
  // openToNanoVDB wants a shared pointer; the deep copy costs host memory of the band once more,
  // which the caller frees with its own grid (the sampler's is a temporary).
  return nanovdb::openToNanoVDB<nanovdb::HostBuffer>(level_set, nanovdb::StatsMode::BBox,
                                                     nanovdb::ChecksumMode::Disable);
}

std::vector<gpu::layout::FieldRootTile> gpu_root_table(const nanovdb::FloatGrid& grid) {
  using Root = nanovdb::FloatGrid::TreeType::RootType;
  const Root& root = grid.tree().root();
  const auto* base = reinterpret_cast<const char*>(&grid);
  const auto offset_of = [&](const void* p) {
    const std::ptrdiff_t offset = static_cast<const char*>(p) - base;
    if (offset < 0 || offset > static_cast<std::ptrdiff_t>(UINT32_MAX)) {
      throw Error(ExitCode::Internal, "gpu_root_table: a root tile lies past the 32-bit addresses PNanoVDB reads");
    }
    return static_cast<std::uint32_t>(offset);
  };
  std::vector<gpu::layout::FieldRootTile> table;
  table.reserve(root.tileCount());
  for (std::uint32_t t = 0; t < root.tileCount(); ++t) {
    const Root::DataType::Tile* tile = root.data()->tile(t);
    const nanovdb::Coord origin = tile->origin();
    gpu::layout::FieldRootTile entry{};
    entry.origin = {origin.x(), origin.y(), origin.z(), tile->isActive() ? 1 : 0};
    entry.address.x = tile->isChild() ? offset_of(root.data()->getChild(tile)) : 0u;
    entry.address.y = offset_of(&tile->value);
    table.push_back(entry);
  }
  // The GLSL binary search compares x, then y, then z as signed ints.
  std::sort(table.begin(), table.end(), [](const auto& a, const auto& b) {
    return std::tie(a.origin.x, a.origin.y, a.origin.z) < std::tie(b.origin.x, b.origin.y, b.origin.z);
  });
  return table;
}

namespace {

// The largest resolution (voxels along the longest side) whose field fits `limit` bytes: the band,
// and so the grid, grows as the square of the resolution.
int largest_fitting_resolution(const GridSpec& spec, std::size_t bytes, std::size_t limit) {
  const int longest = std::max({spec.dims.x(), spec.dims.y(), spec.dims.z()});
  return static_cast<int>(std::floor(longest * std::sqrt(static_cast<double>(limit) / static_cast<double>(bytes))));
}

}  // namespace

SparseField::SparseField(const openvdb::FloatGrid& level_set, const GridSpec& spec, double band_voxels)
    : SparseField(to_nanovdb(level_set), spec, band_voxels) {}

SparseField::SparseField(NanoGrid grid, const GridSpec& spec, double band_voxels, std::size_t block_bytes)
    : spec_(spec),
      band_(band_voxels),
      background_(static_cast<float>(band_voxels * spec.voxel_size)),
      host_(std::move(grid)) {
  const nanovdb::FloatGrid* nano = host_.grid<float>();
  if (!nano) throw Error(ExitCode::Internal, "SparseField: the NanoVDB grid is not a float grid");
  band_voxels_ = nano->activeVoxelCount();
  if (block_bytes == 0) {
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    block_bytes = static_cast<std::size_t>(std::max<GLint64>(max_block, 0));
  }
  const std::size_t bytes = host_.size();
  // PNanoVDB addresses the grid with 32-bit byte offsets, whatever the blocks.
  const std::size_t address_limit = std::size_t{1} << 32;
  // One block when the grid fits; else chunks of a power of two words (the GLSL splits an address
  // with a shift and a mask), the largest that fits a block.
  std::size_t chunk_bytes = bytes;
  if (bytes > block_bytes) {
    chunk_bytes = 4;
    while (chunk_bytes * 2 <= block_bytes) chunk_bytes *= 2;
  }
  const std::size_t limit = std::min(address_limit, chunk_bytes * kMaxFieldChunks);
  if (bytes > limit || block_bytes < 4) {
    throw GpuError(fmt::format("the sparse SDF ({} band voxels, {:.1f} MiB) exceeds what this GPU's storage blocks "
                               "hold ({} of {:.1f} MiB, {:.1f} MiB in all); the largest grid that fits has about {} "
                               "voxels along its longest side (use a larger voxel)",
                               band_voxels_, bytes / 1048576.0, kMaxFieldChunks, chunk_bytes / 1048576.0,
                               limit / 1048576.0, largest_fitting_resolution(spec, bytes, limit)));
  }
  if (chunk_bytes < bytes) {
    while ((std::size_t{4} << chunk_shift_) < chunk_bytes) ++chunk_shift_;
  }
  try {
    const auto* data = static_cast<const std::uint8_t*>(host_.data());
    for (std::size_t offset = 0; offset < bytes; offset += chunk_bytes) {
      chunks_.emplace_back(std::min(chunk_bytes, bytes - offset), data + offset);
    }
    upload_root_table(*nano);
  } catch (const GpuError& e) {
    chunks_.clear();
    throw GpuError(fmt::format("{} for the sparse SDF ({} band voxels); the largest grid that might fit has about {} "
                               "voxels along its longest side",
                               e.what(), band_voxels_, largest_fitting_resolution(spec, bytes, bytes / 2)));
  }
}

void SparseField::upload_root_table(const nanovdb::FloatGrid& grid) {
  std::vector<gpu::layout::FieldRootTile> table = gpu_root_table(grid);
  root_tiles_ = static_cast<int>(table.size());
  background_address_ = static_cast<std::uint32_t>(reinterpret_cast<const char*>(&grid.tree().root().background()) -
                                                   reinterpret_cast<const char*>(&grid));
  if (table.empty()) table.emplace_back();  // GL has no empty buffers; the reader searches none of it
  roots_ = gpu::Buffer::from<gpu::layout::FieldRootTile>(table);
}

std::size_t SparseField::gpu_bytes() const {
  std::size_t bytes = roots_.bytes();
  for (const auto& chunk : chunks_) bytes += chunk.bytes();
  return bytes;
}

std::vector<std::string> SparseField::shader_defines() const {
  if (chunks_.size() <= 1) return {};
  return {fmt::format("TS_FIELD_CHUNKS {}", chunks_.size()), fmt::format("TS_FIELD_CHUNK_SHIFT {}", chunk_shift_)};
}

void SparseField::bind(const FieldSlots& slots) const {
  for (std::size_t c = 0; c < chunks_.size(); ++c) chunks_[c].bind(c == 0 ? slots.first : slots.more[c - 1]);
  roots_.bind(slots.roots);
  const Eigen::Vector3i offset = spec_.index_offset;
  // The corner count is read only by a chunked field's programs (TS_FIELD_CHUNKS > 1).
  params_.values.index_offset = {offset.x(), offset.y(), offset.z(), chunks_.size() > 1 ? 8 : 0};
  params_.values.scale = {static_cast<float>(spec_.voxel_size), background_, 0.0f, 0.0f};
  params_.values.roots = {static_cast<std::uint32_t>(root_tiles_), background_address_, 0u, 0u};
  params_.bind(slots.params);
}

void write_nvdb(const std::filesystem::path& file, const NanoGrid& grid, const std::vector<std::filesystem::path>& inputs) {
  // Through the checked stream of core/atomic_file.h: NanoVDB's writer by name never checks its writes.
  write_stream_atomically(
      file,
      [&](std::ostream& out) {
        try {
          nanovdb::io::writeGrid(out, grid, nanovdb::io::Codec::NONE);
        } catch (const std::exception& e) {
          throw InputError(file, fmt::format("cannot write the NanoVDB file: {}", e.what()));
        }
      },
      inputs);
}

}  // namespace ts::sdf
