#pragma once
// The narrow-band SDF where the GPU reads it: a NanoVDB float level set (signed distance in world
// units in the band, +-band off it with the sign of the flood fill) in one shader storage buffer, or
// in up to kMaxFieldChunks of them when it is larger than the GPU's largest storage block, with its root
// as a flat table in one more (gpu_root_table), read in GLSL through NanoVDB's PNanoVDB.h below the root
// (shaders/common/sparse_field.glsl: trilinear values and central-difference gradients). GPU memory follows the band (its leaves), not the bounding box:
// doubling the resolution multiplies it by about 4, not 8. Used by the sampler and the preview.
#include <openvdb/openvdb.h>

#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/HostBuffer.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <map>
#include <string>
#include <vector>

#include "gpu/gl.h"
#include "gpu/layouts.h"
#include "gpu/params.h"
#include "sdf/gpu_field.h"
#include "sdf/grid.h"

namespace ts::sdf {

using NanoGrid = nanovdb::GridHandle<nanovdb::HostBuffer>;

// A float level set as a NanoVDB grid on the host (no checksum; min/max/bbox statistics on), in the
// level set's own index space (.nvdb output, the CPU's sdf::HostField).
NanoGrid to_nanovdb(const openvdb::FloatGrid& level_set);

// The root of a NanoVDB grid as the GPU reads it (shaders/common/sparse_field.glsl, field_root_find):
// one entry per tile of the box of root tiles the grid spans, x slowest and z fastest, with the byte
// offsets of the tile's upper node (0 for none) and of its value in the grid; a box tile the grid lacks
// reads as the background. The GLSL reader finds a coordinate's entry by arithmetic on these 32-bit
// ints instead of PNanoVDB's root walk, whose 64-bit key NVIDIA's GLSL compiler (driver 580.159.04,
// H200, seen 2026-12-04) computed wrong: the walk found no tile and every read was the background.
// Any grid size and any coordinate sign.
struct GpuRootTable {
  Eigen::Vector3i first_tile = Eigen::Vector3i::Zero();  // tile index (origin / 4096) of entry 0
  Eigen::Vector3i extent = Eigen::Vector3i::Zero();      // the box [root tiles]; zero for a grid without tiles
  std::uint32_t background_address = 0;                  // byte offset of the root's background value
  std::vector<gpu::layout::FieldRootTile> entries;
};
// Throws GpuError when the box would pass kMaxRootTableEntries (root tiles far apart: a grid no level set
// of ours makes) and Error (internal) when an offset passes 32 bits.
inline constexpr std::size_t kMaxRootTableEntries = std::size_t{1} << 20;
GpuRootTable gpu_root_table(const nanovdb::FloatGrid& grid);

class SparseField final : public GpuField {
 public:
  SparseField() = default;
  // `level_set`: a float level set whose index space is `spec`'s (voxel (i, j, k) of the spec at
  // index spec.index_offset + (i, j, k)), values in world units, background band * voxel_size,
  // flood-filled. Converted to NanoVDB and uploaded; throws GpuError (exit 3) when the GPU cannot
  // hold it, naming the size and the largest resolution that would fit.
  SparseField(const openvdb::FloatGrid& level_set, const GridSpec& spec, double band_voxels);
  // The same from a grid already converted by to_nanovdb(level_set) and checked by the caller.
  // `block_bytes`: the largest storage block to use, 0 for the GPU's own (GL_MAX_SHADER_STORAGE_BLOCK_SIZE);
  // tests pass a small one to cut a small grid into chunks.
  SparseField(NanoGrid grid, const GridSpec& spec, double band_voxels, std::size_t block_bytes = 0);

  const GridSpec& spec() const override { return spec_; }
  double band() const { return band_; }                 // half-width [voxels]
  float background() const { return background_; }      // +-this off the band [world units]
  bool empty() const override { return chunks_.empty(); }
  std::size_t gpu_bytes() const override;
  // Storage blocks holding the grid (1 when it fits one), each 2^chunk_shift() words but the last.
  int chunk_count() const { return static_cast<int>(chunks_.size()); }
  int chunk_shift() const { return chunk_shift_; }
  // What a program that reads this field is compiled with (gpu::Program's defines): nothing for one
  // block, else the chunk count and size that shaders/common/sparse_field.glsl branches on. A program
  // compiled for one field reads another only if their defines are equal.
  std::vector<std::string> shader_defines() const override;
  std::size_t band_voxels() const { return band_voxels_; }  // active voxels of the level set
  const NanoGrid& host() const { return host_; }         // the uploaded bytes (tests), in the level set's index space
  const GpuRootTable& root_table() const { return roots_table_; }  // what the root table's buffer holds

  // Binds the grid's chunks, its root table and the parameters shaders/common/sparse_field.glsl reads to `slots`.
  void bind(const FieldSlots& slots) const override;

 private:
  // Builds and uploads the root table of `grid` (the uploaded one).
  void upload_root_table(const nanovdb::FloatGrid& grid);

  GridSpec spec_;
  double band_ = 0.0;
  float background_ = 0.0f;
  std::size_t band_voxels_ = 0;
  NanoGrid host_;
  int chunk_shift_ = 0;  // log2 of a chunk's words; 0 for one block
  std::vector<gpu::Buffer> chunks_;
  GpuRootTable roots_table_;
  gpu::Buffer roots_;  // roots_table_.entries (one zero entry for a grid without tiles)
  // Where the grid sits; mutable: bind() uploads it on first use, from a const field.
  mutable gpu::ParamBlock<gpu::params::FieldParams> params_;
};

// How a .nvdb file's grid is compressed: NanoVDB's own file codecs, which nanovdb_print, nanovdb_validate
// and nanovdb_convert read as Debian builds them; a reader decompresses on loading, so the GPU field
// (PNanoVDB) sees the same grid whatever the codec. Zip is the smallest on the bundled meshes (bunny at
// 64 voxels: 3.1 MB none, 0.29 MB blosc, 0.24 MB zip), hence the default.
enum class NvdbCodec { None, Zip, Blosc };
// "none", "zip" or "blosc"; nullopt for anything else.
std::optional<NvdbCodec> parse_nvdb_codec(std::string_view name);

// Writes `grid` as a NanoVDB file compressed with `codec`, atomically, with a full checksum set in
// `grid` first (so damage is told on reading); `inputs` are never overwritten (core/atomic_file.h).
void write_nvdb(const std::filesystem::path& file, NanoGrid& grid, const std::vector<std::filesystem::path>& inputs,
                NvdbCodec codec = NvdbCodec::Zip);

}  // namespace ts::sdf
