#pragma once
// The narrow-band SDF where the GPU reads it: a NanoVDB float level set (signed distance in world
// units in the band, +-band off it with the sign of the flood fill) in shader storage buffers, read
// in GLSL through NanoVDB's PNanoVDB.h (shaders/common/sparse_field.glsl: trilinear values and
// central-difference gradients). GPU memory follows the band (its leaves), not the bounding box:
// doubling the resolution multiplies it by about 4, not 8. Used by the sampler and the preview.
// A grid larger than one storage block (GL_MAX_SHADER_STORAGE_BLOCK_SIZE: 128 MiB on llvmpipe) is
// split into up to TS_FIELD_CHUNKS equal power-of-two chunks, each its own buffer and slot.
#include <openvdb/openvdb.h>

#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/HostBuffer.h>

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "gpu/gl.h"
#include "sdf/grid.h"

namespace ts::sdf {

using NanoGrid = nanovdb::GridHandle<nanovdb::HostBuffer>;

// A float level set as a NanoVDB grid on the host (no checksum; min/max/bbox statistics on).
NanoGrid to_nanovdb(const openvdb::FloatGrid& level_set);

class SparseField {
 public:
  SparseField() = default;
  // `level_set`: a float level set whose index space is `spec`'s (voxel (i, j, k) of the spec at
  // index spec.index_offset + (i, j, k)), values in world units, background band * voxel_size,
  // flood-filled. Converted to NanoVDB and uploaded; throws GpuError (exit 3) when the GPU cannot
  // hold it, naming the size and the largest resolution that would fit.
  SparseField(const openvdb::FloatGrid& level_set, const GridSpec& spec, double band_voxels);
  // The same from a grid already converted (to_nanovdb) and checked by the caller. `max_chunk_bytes`
  // (0: the device's largest storage block) caps one chunk; tests set it small to read across chunks.
  SparseField(NanoGrid grid, const GridSpec& spec, double band_voxels, std::size_t max_chunk_bytes = 0);

  const GridSpec& spec() const { return spec_; }
  double band() const { return band_; }                 // half-width [voxels]
  float background() const { return background_; }      // +-this off the band [world units]
  bool empty() const { return chunks_.empty(); }
  std::size_t gpu_bytes() const;                        // the NanoVDB grid, as is, over all chunks
  std::size_t chunk_count() const { return chunks_.size(); }
  std::size_t band_voxels() const { return band_voxels_; }  // active voxels of the level set
  const NanoGrid& host() const { return host_; }         // the uploaded bytes (tests, .nvdb output)

  // Binds the chunks to `first_binding` and the TS_FIELD_CHUNKS - 1 slots after it (a stage's
  // *_SPARSE_FIELD_0 to _3) and sets the uniforms shaders/common/sparse_field.glsl reads. Slots past
  // the last chunk get chunk 0, never read, so that every block the program declares is bound.
  void bind(const gpu::Program& program, GLuint first_binding) const;

 private:
  GridSpec spec_;
  double band_ = 0.0;
  float background_ = 0.0f;
  std::size_t band_voxels_ = 0;
  NanoGrid host_;
  std::vector<gpu::Buffer> chunks_;
  unsigned chunk_shift_ = 0;  // log2 of the 32-bit words one chunk holds
};

// Writes `grid` as a NanoVDB file (uncompressed, readable by nanovdb_print / nanovdb_validate),
// atomically; `inputs` are never overwritten (core/atomic_file.h).
void write_nvdb(const std::filesystem::path& file, const NanoGrid& grid, const std::vector<std::filesystem::path>& inputs);

}  // namespace ts::sdf
