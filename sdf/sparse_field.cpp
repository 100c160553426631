#include "sdf/sparse_field.h"

#include <fmt/format.h>

#include <nanovdb/util/GridChecksum.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

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

GpuRootTable gpu_root_table(const nanovdb::FloatGrid& grid) {
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
  GpuRootTable table;
  table.background_address = offset_of(&root.background());
  if (root.tileCount() == 0) return table;
  // Tile indices (origin >> 12, rounding down) and the box that holds them all.
  const auto tile_of = [](const nanovdb::Coord& origin) {
    return Eigen::Vector3i(origin.x() >> 12, origin.y() >> 12, origin.z() >> 12);
  };
  Eigen::Vector3i lo = Eigen::Vector3i::Constant(INT32_MAX), hi = Eigen::Vector3i::Constant(INT32_MIN);
  for (std::uint32_t t = 0; t < root.tileCount(); ++t) {
    const Eigen::Vector3i index = tile_of(root.data()->tile(t)->origin());
    lo = lo.cwiseMin(index);
    hi = hi.cwiseMax(index);
  }
  table.first_tile = lo;
  table.extent = hi - lo + Eigen::Vector3i::Ones();
  const double cells = static_cast<double>(table.extent.x()) * table.extent.y() * table.extent.z();
  if (cells > static_cast<double>(kMaxRootTableEntries)) {
    throw GpuError(fmt::format("the sparse SDF's {} root tiles span a box of {:.0f} tiles, more than the {} the GPU "
                               "root table holds", root.tileCount(), cells, kMaxRootTableEntries));
  }
  table.entries.resize(static_cast<std::size_t>(cells));
  for (std::size_t n = 0; n < table.entries.size(); ++n) {  // tiles the grid lacks: the background
    const auto i = static_cast<int>(n / (table.extent.y() * table.extent.z()));
    const auto j = static_cast<int>(n / table.extent.z() % table.extent.y());
    const auto k = static_cast<int>(n % table.extent.z());
    const Eigen::Vector3i origin = (lo + Eigen::Vector3i(i, j, k)) * 4096;
    table.entries[n].origin = {origin.x(), origin.y(), origin.z(), 0};
    table.entries[n].address = {0u, table.background_address, 0u, 0u};
  }
  for (std::uint32_t t = 0; t < root.tileCount(); ++t) {
    const Root::DataType::Tile* tile = root.data()->tile(t);
    const Eigen::Vector3i rel = tile_of(tile->origin()) - lo;
    gpu::layout::FieldRootTile& entry =
        table.entries[(static_cast<std::size_t>(rel.x()) * table.extent.y() + rel.y()) * table.extent.z() + rel.z()];
    entry.origin.w = tile->isActive() ? 1 : 0;
    entry.address = {tile->isChild() ? offset_of(root.data()->getChild(tile)) : 0u, offset_of(&tile->value), 1u, 0u};
  }
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
  roots_table_ = gpu_root_table(grid);
  std::vector<gpu::layout::FieldRootTile> entries = roots_table_.entries;
  if (entries.empty()) entries.emplace_back();  // GL has no empty buffers; an empty box reads none of it
  roots_ = gpu::Buffer::from<gpu::layout::FieldRootTile>(entries);
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
  const GpuRootTable& t = roots_table_;
  params_.values.root_first = {t.first_tile.x(), t.first_tile.y(), t.first_tile.z(), 0};
  params_.values.roots = {static_cast<std::uint32_t>(t.extent.x()), static_cast<std::uint32_t>(t.extent.y()),
                          static_cast<std::uint32_t>(t.extent.z()), t.background_address};
  params_.bind(slots.params);
}

std::optional<NvdbCodec> parse_nvdb_codec(std::string_view name) {
  if (name == "none") return NvdbCodec::None;
  if (name == "zip") return NvdbCodec::Zip;
  if (name == "blosc") return NvdbCodec::Blosc;
  return std::nullopt;
}

void write_nvdb(const std::filesystem::path& file, NanoGrid& grid, const std::vector<std::filesystem::path>& inputs,
                NvdbCodec codec) {
  const nanovdb::io::Codec nano_codec = codec == NvdbCodec::Zip     ? nanovdb::io::Codec::ZIP
                                        : codec == NvdbCodec::Blosc ? nanovdb::io::Codec::BLOSC
                                                                    : nanovdb::io::Codec::NONE;
  // A full checksum (a CRC over the whole grid), so a damaged file is told by tetrasand's reader and by
  // NanoVDB's own validator instead of being read as another field.
  nanovdb::updateChecksum(*grid.grid<float>(), nanovdb::ChecksumMode::Full);
  // Through the checked stream of core/atomic_file.h: NanoVDB's writer by name never checks its writes.
  write_stream_atomically(
      file,
      [&](std::ostream& out) {
        try {
          nanovdb::io::writeGrid(out, grid, nano_codec);
        } catch (const std::exception& e) {
          throw InputError(file, fmt::format("cannot write the NanoVDB file: {}", e.what()));
        }
      },
      inputs);
}

}  // namespace ts::sdf
