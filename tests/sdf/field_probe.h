#pragma once
// Reads a GPU field (sdf::SparseField or sdf::LeafField) through the shaders' own sparse_field.glsl
// functions, so the tests check what the sampler's kernels will see, not a host copy.
#include <Eigen/Core>
#include <vector>

#include "sdf/gpu_field.h"

namespace ts::test {

// Runs shaders/test/sparse_field_probe.comp on `field` at grid-local `points` [voxels]; `mode` is the
// kernel's TS_PROBE_MODE (0: the voxel value, 1: trilinear, 2: field_sample's gradient and value; the
// shader lists the others).
std::vector<Eigen::Vector4f> probe_field(const sdf::GpuField& field,
                                         const std::vector<Eigen::Vector4f>& points, int mode);

}  // namespace ts::test
