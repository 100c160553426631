#include "sdf/sparse_field.h"

#include <fmt/format.h>

#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include <cmath>

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

Eigen::Vector3i gpu_index_shift(const GridSpec& spec) {
  Eigen::Vector3i shift;
  for (int a = 0; a < 3; ++a) shift[a] = -static_cast<int>(std::floor(spec.index_offset[a] / 128.0)) * 128;
  return shift;
}

NanoGrid to_gpu_nanovdb(const openvdb::FloatGrid& level_set, const GridSpec& spec) {
  const Eigen::Vector3i s = gpu_index_shift(spec);
  if (s.isZero()) return to_nanovdb(level_set);
  const openvdb::Coord shift(s.x(), s.y(), s.z());
  // A copy of the band moved by `shift`: leaves keep their voxels (the shift is a multiple of 8), tiles
  // (the flood fill's inside and any constant region) are filled at their moved boxes.
  openvdb::FloatGrid::Ptr moved = openvdb::FloatGrid::create(level_set.background());
  moved->setGridClass(level_set.getGridClass());
  moved->setTransform(level_set.transform().copy());
  openvdb::FloatTree& tree = moved->tree();
  for (auto leaf = level_set.tree().cbeginLeaf(); leaf; ++leaf) {
    auto* copy = new openvdb::FloatTree::LeafNodeType(*leaf);
    copy->setOrigin(leaf->origin() + shift);
    tree.addLeaf(copy);
  }
  for (auto tile = level_set.tree().cbeginValueAll(); tile; ++tile) {
    if (!tile.isTileValue()) continue;
    openvdb::CoordBBox box = tile.getBoundingBox();
    box.translate(shift);
    tree.fill(box, *tile, tile.isValueOn());
  }
  return to_nanovdb(*moved);
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
    : SparseField(to_gpu_nanovdb(level_set, spec), spec, band_voxels) {}

SparseField::SparseField(NanoGrid grid, const GridSpec& spec, double band_voxels, std::size_t block_bytes)
    : spec_(spec),
      band_(band_voxels),
      background_(static_cast<float>(band_voxels * spec.voxel_size)),
      host_(std::move(grid)) {
  const nanovdb::FloatGrid* nano = host_.grid<float>();
  if (!nano) throw Error(ExitCode::Internal, "SparseField: the NanoVDB grid is not a float grid");
  band_voxels_ = nano->activeVoxelCount();
  const Eigen::Vector3i far_corner = gpu_index_offset() + spec.dims - Eigen::Vector3i::Ones();
  if (far_corner.maxCoeff() >= 4096) {
    log::warn("the sparse SDF is {} voxels along its longest side: past 4096 voxels from its corner the GPU "
              "reads walk NanoVDB's root, which NVIDIA's driver 580 computed wrong (docs/architecture.md, "
              "\"The GPU field\"); on an NVIDIA GPU prefer a coarser voxel or the CPU path (--backend cpu)",
              spec.dims.maxCoeff());
  }
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
  } catch (const GpuError& e) {
    chunks_.clear();
    throw GpuError(fmt::format("{} for the sparse SDF ({} band voxels); the largest grid that might fit has about {} "
                               "voxels along its longest side",
                               e.what(), band_voxels_, largest_fitting_resolution(spec, bytes, bytes / 2)));
  }
}

std::size_t SparseField::gpu_bytes() const {
  std::size_t bytes = 0;
  for (const auto& chunk : chunks_) bytes += chunk.bytes();
  return bytes;
}

std::vector<std::string> SparseField::shader_defines() const {
  if (chunks_.size() <= 1) return {};
  return {fmt::format("TS_FIELD_CHUNKS {}", chunks_.size()), fmt::format("TS_FIELD_CHUNK_SHIFT {}", chunk_shift_)};
}

void SparseField::bind(const FieldSlots& slots) const {
  for (std::size_t c = 0; c < chunks_.size(); ++c) chunks_[c].bind(c == 0 ? slots.first : slots.more[c - 1]);
  const Eigen::Vector3i offset = gpu_index_offset();
  // The corner count is read only by a chunked field's programs (TS_FIELD_CHUNKS > 1).
  params_.values.index_offset = {offset.x(), offset.y(), offset.z(), chunks_.size() > 1 ? 8 : 0};
  params_.values.scale = {static_cast<float>(spec_.voxel_size), background_, 0.0f, 0.0f};
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
