#pragma once
// The narrow-band SDF where the GPU reads it: a NanoVDB float level set (signed distance in world
// units in the band, +-band off it with the sign of the flood fill) in one shader storage buffer,
// read in GLSL through NanoVDB's PNanoVDB.h (shaders/common/sparse_field.glsl: trilinear values and
// central-difference gradients). GPU memory follows the band (its leaves), not the bounding box:
// doubling the resolution multiplies it by about 4, not 8. Used by the sampler and the preview.
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
  // The same from a grid already converted (to_nanovdb) and checked by the caller.
  SparseField(NanoGrid grid, const GridSpec& spec, double band_voxels);

  const GridSpec& spec() const { return spec_; }
  double band() const { return band_; }                 // half-width [voxels]
  float background() const { return background_; }      // +-this off the band [world units]
  const gpu::Buffer& buffer() const { return buffer_; }  // the NanoVDB grid, as is
  bool empty() const { return buffer_.id() == 0; }
  std::size_t gpu_bytes() const { return buffer_.bytes(); }
  std::size_t band_voxels() const { return band_voxels_; }  // active voxels of the level set
  const NanoGrid& host() const { return host_; }         // the uploaded bytes (tests, .nvdb output)

  // Binds the grid to `binding` and sets the uniforms shaders/common/sparse_field.glsl reads.
  void bind(const gpu::Program& program, GLuint binding) const;

 private:
  GridSpec spec_;
  double band_ = 0.0;
  float background_ = 0.0f;
  std::size_t band_voxels_ = 0;
  NanoGrid host_;
  gpu::Buffer buffer_;
};

// Writes `grid` as a NanoVDB file (uncompressed, readable by nanovdb_print / nanovdb_validate),
// atomically; `inputs` are never overwritten (core/atomic_file.h).
void write_nvdb(const std::filesystem::path& file, const NanoGrid& grid, const std::vector<std::filesystem::path>& inputs);

}  // namespace ts::sdf
