#pragma once
// The narrow-band SDF built by the scan conversion on the GPU and kept there (issue 43, "the field
// stays on the GPU"): 8^3 leaves from grid-local voxel (0,0,0), a dense uint index over the grid's
// leaf cells (the leaf's slot, or a code for a cell without band voxels: all inside or all outside),
// and 512 floats a band leaf (world units; band voxels as scanned, the others +-background with the
// flood fill's sign). shaders/common/sparse_field.glsl reads it (TS_FIELD_LEAVES) behind the same
// functions as the NanoVDB field, voxel for voxel the same values as the host's level set from the
// same scan (tests/sdf/leaf_field_test.cpp), so the sampler's kernels run on it unchanged and no byte
// of the field crosses to the host. Layout: shaders/common/layouts.h; kernels: shaders/sdf/leaf_*.comp.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "gpu/gl.h"
#include "gpu/graphics.h"
#include "gpu/hash_grid.h"
#include "gpu/params.h"
#include "sdf/gpu_field.h"
#include "sdf/grid.h"

namespace ts::sdf {

inline constexpr int kLeafSide = 8;
inline constexpr std::size_t kLeafVoxels = 512;
inline constexpr std::size_t kLeafBytes = kLeafVoxels * sizeof(float);
// Slots stay far below the TS_LEAF_* codes (shaders/common/layouts.h) and their word addresses
// (slot * 512) within 32 bits.
inline constexpr std::size_t kMaxLeafSlots = std::size_t{1} << 23;

// Leaf cells along x, y, z: ceil(dims / 8).
Eigen::Vector3i leaf_cells(const GridSpec& spec);

// An upper bound on the band leaves of `mesh` on `spec`, known before the scan: the leaf cells whose
// box comes within `band` (+ the scan's quarter voxel) of a triangle's plane inside the triangle's
// grown bounding box. What the leaf field allocates.
std::size_t band_leaf_bound(const TriangleMesh& mesh, const GridSpec& spec, double band);

// GPU bytes of a leaf field with `slots` leaf slots on `spec` (index and values).
std::size_t leaf_field_bytes(const GridSpec& spec, std::size_t slots);

// The GPU memory a field may take: TETRASAND_GPU_MEMORY_MIB when set (tests; a cap below the card's),
// else the free video memory the driver reports (GL_NVX_gpu_memory_info), else no limit (0).
std::size_t gpu_field_memory_limit();

class LeafField final : public GpuField {
 public:
  LeafField() = default;
  // Allocates `slots` leaf slots (contents undefined until a LeafFieldBuilder fills them). Throws
  // GpuError when the values pass the GPU's largest storage block or kMaxLeafSlots.
  LeafField(const GridSpec& spec, double band_voxels, std::size_t slots);

  const GridSpec& spec() const override { return spec_; }
  bool empty() const override { return slots_ == 0; }
  std::size_t gpu_bytes() const override { return index_.bytes() + values_.bytes(); }
  std::vector<std::string> shader_defines() const override { return {"TS_FIELD_LEAVES 1"}; }
  void bind(const FieldSlots& slots) const override;

  double band() const { return band_; }             // half-width [voxels]
  float background() const { return background_; }  // +-this off the band [world units]
  Eigen::Vector3i cells() const { return leaf_cells(spec_); }
  std::size_t slots() const { return slots_; }              // allocated
  std::size_t band_leaves() const { return band_leaves_; }  // used, once built
  std::size_t band_voxels() const { return band_voxels_; }  // once built

  // The index (one entry per leaf cell) and the band leaves' values, read back: for tests and files.
  struct HostCopy {
    std::vector<std::uint32_t> index;
    std::vector<float> values;  // kLeafVoxels per band leaf, in slot order
  };
  HostCopy download() const;

 private:
  friend class LeafFieldBuilder;
  GridSpec spec_;
  double band_ = 0.0;
  float background_ = 0.0f;
  std::size_t slots_ = 0, band_leaves_ = 0, band_voxels_ = 0;
  gpu::Buffer index_, values_;
  mutable gpu::ParamBlock<gpu::params::FieldParams> params_;  // uploaded by bind()
};

// Builds a LeafField from the scan conversion's slabs, each as soon as it is filled, on the GPU:
// band leaves flagged, slots from an exclusive scan (deterministic), values copied out of the slab
// target with the within-leaf sign fill; after the last slab the cells without band voxels take
// their sign. Slabs must start at multiples of 8 layers.
class LeafFieldBuilder {
 public:
  LeafFieldBuilder(const gpu::ShaderLibrary& library, gpu::Queue& queue, LeafField& field);
  // `slab`: the filled slab target (RGBA32F array, w: distance [voxels], layer 0 at grid z `z0`).
  void add_slab(const gpu::Texture& slab, int z0, int layers);
  // Gives the cells without band voxels their sign, then reads back the counters (16 bytes, not
  // field bytes): the band leaves and voxels. Throws Error (internal) when the leaves outgrew the slots.
  void finish();
  std::size_t gpu_bytes() const { return flags_.bytes() + counts_.bytes(); }  // besides the field

 private:
  void dispatch(const gpu::Program& program, std::size_t items, GLbitfield barrier = GL_SHADER_STORAGE_BARRIER_BIT);
  LeafField& field_;
  gpu::Queue& queue_;
  gpu::Program flag_, assign_, fill_, signs_;
  gpu::PrefixScan scan_;
  gpu::Buffer flags_, counts_;
  gpu::ParamBlock<gpu::params::LeafBuildParams> params_;
  int slabs_ = 0;
};

}  // namespace ts::sdf
