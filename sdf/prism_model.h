#pragma once
// The work the geometry-shader scan conversion (shaders/sdf/scan_convert.geom) should make of its prisms,
// worked out on the host by the shader's own slicing rules, to hold the GPU's pipeline statistics
// against (gpu::PipelineStatistics; docs/benchmarks/sdf.md, "Geometry path: pipeline statistics against the
// prism model"). A count that differs from the model means the shader does other work than the design says.
#include <cstdint>
#include <span>

#include "gpu/layouts.h"

namespace ts::sdf {

struct PrismWorkModel {
  // Cross-sections the geometry shader emits: a tetrahedron cut by a voxel-centre plane z = k gives a
  // triangle (1 primitive) or a quad (a 4-vertex strip: 2 primitives).
  std::uint64_t primitives = 0;
  // The prisms' summed volume [voxels^3]: the voxel centres inside them, so about the fragments drawn.
  double volume = 0.0;
};

// `prisms` in grid-local voxel units (gpu::layout::SdfPrism), `drawn` the indices the draws use,
// `z_layers` the grid's layers (the shader draws none outside [0, z_layers)). In float, as the shader.
PrismWorkModel model_prism_work(std::span<const gpu::layout::SdfPrism> prisms,
                                std::span<const std::uint32_t> drawn, int z_layers);

}  // namespace ts::sdf
