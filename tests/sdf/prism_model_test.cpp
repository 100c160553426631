// The geometry path's pipeline statistics (gpu::PipelineStatistics) against the prism model
// (sdf/prism_model.h): the draws run the geometry-shader invocations they ask for, the shader emits the
// cross-sections its slicing rules give, and the fragments are about the voxel centres inside the prisms.
#include "sdf/prism_model.h"

#include <gtest/gtest.h>

#include "core/mesh_io.h"
#include "core/primitives.h"
#include "gpu/context.h"
#include "gpu/graphics.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

ScanConvertResult scan(gpu::Context& context, const TriangleMesh& mesh, int resolution, ScanMethod method,
                       std::size_t max_slab_bytes = std::size_t{1} << 30) {
  SdfSettings settings;
  settings.resolution = resolution;
  ScanConvertOptions options;
  options.method = method;
  options.pipeline_statistics = true;
  options.build_grid = false;
  options.max_slab_bytes = max_slab_bytes;
  return scan_convert(context, mesh, compute_pseudonormals(mesh), make_grid(bounding_box(mesh), settings),
                      options);
}

TEST(PrismModel, AxisAlignedPrismIsSlicedIntoTheCrossSectionsOfItsLayers) {
  // A right triangle in the plane z = 2.5 grown into a prism of half-height 1: the voxel-centre planes
  // z = 2 and z = 3 cut it; each cut meets the three tetrahedra of the split in 1 + 2 + 1 primitives
  // (the middle one crosses with two corners on each side). Volume: area 0.5 x height 2.
  gpu::layout::SdfPrism prism{};
  prism.corner[0] = {0.0f, 0.0f, 2.5f, 3.0f};
  prism.corner[1] = {1.0f, 0.0f, 2.5f, 0.0f};
  prism.corner[2] = {0.0f, 1.0f, 2.5f, 0.0f};
  prism.corner[3] = prism.corner[2];
  prism.normal_margin = {0.0f, 0.0f, 1.0f, 1.0f};
  const std::uint32_t drawn[] = {0};
  const PrismWorkModel model = model_prism_work({&prism, 1}, drawn, 8);
  EXPECT_DOUBLE_EQ(model.volume, 1.0);
  EXPECT_EQ(model.primitives, 2u * 4u);
  // Layers outside the grid are never drawn.
  EXPECT_EQ(model_prism_work({&prism, 1}, drawn, 3).primitives, 4u);
}

TEST(PrismModel, GeometryPathDoesTheWorkThePrismModelPredicts) {
  gpu::Context context;
  if (!gpu::PipelineStatistics::available())
    GTEST_SKIP() << "no pipeline statistics queries on " << context.summary();
  for (const char* name : {"knot1", "fandisk"}) {
    const TriangleMesh mesh = load_mesh(test::cgal_mesh(name));
    // Small slabs too: the counts add up over slabs and draws.
    for (std::size_t slab_bytes : {std::size_t{1} << 30, std::size_t{1} << 20}) {
      const ScanConvertResult result = scan(context, mesh, 40, ScanMethod::Geometry, slab_bytes);
      const ScanPipelineWork& p = result.stats.pipeline;
      ASSERT_TRUE(p.measured) << name;
      // The spec counts each geometry-shader instance; llvmpipe counts one per input primitive.
      EXPECT_TRUE(p.geometry_invocations == p.model_invocations || p.geometry_invocations == p.drawn_prisms)
          << name << ": " << p.geometry_invocations << " invocations, " << p.model_invocations
          << " instances of " << p.drawn_prisms << " prisms";
      // Float slicing on both sides; a corner exactly on a voxel-centre plane could round either way.
      EXPECT_NEAR(static_cast<double>(p.geometry_primitives), static_cast<double>(p.model_primitives),
                  1e-3 * static_cast<double>(p.model_primitives))
          << name;
      // Every voxel centre inside a prism is shaded once at least (llvmpipe shades whole 4x4 blocks and
      // counts 16 each, so the count is only a lower bound across drivers), and so is every band voxel.
      EXPECT_GE(static_cast<double>(p.fragments), 0.98 * p.model_volume) << name;
      EXPECT_GE(p.fragments, result.stats.band_voxels) << name;
    }
  }
}

TEST(PrismModel, ComputePathReportsNoPipelineStatistics) {
  gpu::Context context;
  const ScanConvertResult result = scan(context, make_icosphere(0.5, 2), 16, ScanMethod::Compute);
  EXPECT_FALSE(result.stats.pipeline.measured);
  EXPECT_EQ(result.stats.pipeline.fragments, 0u);
}

}  // namespace
}  // namespace ts::sdf
