#pragma once
// A narrow-band SDF as the GPU's kernels read it through shaders/common/sparse_field.glsl
// (field_voxel, field_trilinear, field_sample): a NanoVDB grid uploaded from the host (sdf::SparseField)
// or the leaf field the scan conversion builds and keeps on the GPU (sdf::LeafField). A kernel is
// compiled with the field's shader_defines() and reads it through the slots bind() fills.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "gpu/gl.h"
#include "sdf/grid.h"

namespace ts::sdf {

// At most this many storage blocks hold one field (shaders/common/sparse_field.glsl): 1 GiB on
// llvmpipe's 128 MiB blocks. A kernel reads the field through chunk 0's slot and 7 more its stage names.
inline constexpr int kMaxFieldChunks = 8;

// Where a stage binds the field: chunk 0's slot and the slots of chunks 1-7 (shaders/<stage>/bindings.h).
struct FieldSlots {
  GLuint first = 0;
  std::array<GLuint, kMaxFieldChunks - 1> more{};
  GLuint params = 0;  // uniform-block slot of its gpu::params::FieldParams
  GLuint roots = 0;   // slot of its root table (gpu_root_table), or of a leaf field's leaf index
};

class GpuField {
 public:
  virtual ~GpuField() = default;
  virtual const GridSpec& spec() const = 0;
  virtual bool empty() const = 0;
  virtual std::size_t gpu_bytes() const = 0;
  // What a program that reads this field is compiled with (gpu::Program's defines). A program
  // compiled for one field reads another only if their defines are equal.
  virtual std::vector<std::string> shader_defines() const = 0;
  // Binds the field's buffers and the parameters shaders/common/sparse_field.glsl reads to `slots`.
  virtual void bind(const FieldSlots& slots) const = 0;

 protected:
  GpuField() = default;
  GpuField(const GpuField&) = default;
  GpuField(GpuField&&) = default;
  GpuField& operator=(const GpuField&) = default;
  GpuField& operator=(GpuField&&) = default;
};

}  // namespace ts::sdf
