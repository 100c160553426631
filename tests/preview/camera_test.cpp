// The camera: named views, framing that holds the whole box, orbits, matrices.
#include "preview/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "core/error.h"
#include "preview/frame.h"

namespace ts::preview {
namespace {

Eigen::Vector3d project(const ViewMatrices& m, const Eigen::Vector3d& p) {
  const Eigen::Vector4d c = m.projection * m.view * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
  return c.head<3>() / c.w();
}

Aabb test_box() {
  Aabb box;
  box.extend(Eigen::Vector3d(-0.03, 0.0, -0.02));
  box.extend(Eigen::Vector3d(0.05, 0.08, 0.01));
  return box;
}

// Largest |ndc x|, |ndc y| over the box's corners; every corner must lie in front of the near plane.
double extent_in_view(const Camera& c, const Aabb& box, double aspect) {
  const ViewMatrices m = view_matrices(c, aspect, box.center(), 0.5 * box.size().norm());
  double most = 0.0;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p(i & 1 ? box.max.x() : box.min.x(), i & 2 ? box.max.y() : box.min.y(),
                            i & 4 ? box.max.z() : box.min.z());
    const Eigen::Vector3d ndc = project(m, p);
    EXPECT_GT(ndc.z(), -1.0);
    EXPECT_LT(ndc.z(), 1.0);
    most = std::max({most, std::abs(ndc.x()), std::abs(ndc.y())});
  }
  return most;
}

TEST(Camera, NamedViewsFollowTheUpAxis) {
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY(), z = Eigen::Vector3d::UnitZ();
  EXPECT_TRUE(view_direction(View::Front, y).isApprox(z));
  EXPECT_TRUE(view_direction(View::Side, y).isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(view_direction(View::Top, y).isApprox(y));
  EXPECT_TRUE(view_direction(View::Front, z).isApprox(-y));
  EXPECT_TRUE(view_direction(View::Side, z).isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(view_direction(View::Iso, y).isApprox(Eigen::Vector3d(1, 1, 1).normalized()));
  EXPECT_TRUE(view_image_up(View::Top, y).isApprox(-z));
  EXPECT_EQ(parse_view("iso"), View::Iso);
  EXPECT_THROW(parse_view("diagonal"), InputError);
}

TEST(Camera, FramingHoldsEveryCornerTightly) {
  const Aabb box = test_box();
  for (bool ortho : {false, true}) {
    for (View v : {View::Front, View::Side, View::Top, View::Iso}) {
      for (double aspect : {1.0, 1.6, 0.5}) {
        const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
        const Camera c = frame_box(box, view_direction(v, up), view_image_up(v, up), aspect, ortho, 30.0);
        const double extent = extent_in_view(c, box, aspect);
        // The margin (1.08) is on the distance for a pinhole, on the height for a parallel lens.
        EXPECT_LE(extent, ortho ? 1.0 / 1.08 + 1e-9 : 1.0)
            << ortho << " " << static_cast<int>(v) << " " << aspect;
        EXPECT_GT(extent, 0.8) << ortho << " " << static_cast<int>(v) << " " << aspect;
      }
    }
  }
}

TEST(Camera, AzimuthAndElevationGiveTheNamedViews) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  EXPECT_TRUE(view_direction(0.0, 0.0, z).isApprox(view_direction(View::Front, z)));
  EXPECT_TRUE(view_direction(90.0, 0.0, z).isApprox(view_direction(View::Side, z)));
  EXPECT_TRUE(view_direction(45.0, std::atan(1.0 / std::sqrt(2.0)) * 180.0 / std::numbers::pi, z)
                  .isApprox(view_direction(View::Iso, z)));
  EXPECT_NEAR(view_direction(30.0, 30.0, z).z(), 0.5, 1e-12);  // sin 30 degrees above the horizon
}

// The tight fit holds every corner and touches the image's edge on both sides of its binding axis, where
// frame_box, centred on the box, leaves the far side of a perspective view short of the edge.
TEST(Camera, TightFramingTouchesBothEdgesOfItsBindingAxis) {
  const Aabb box = test_box();
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  for (double aspect : {1.0, 4.0 / 3.0, 0.5}) {
    const Camera c = frame_box_tightly(box, view_direction(30.0, 30.0, up), up, aspect, 30.0, 1.0);
    const ViewMatrices m = view_matrices(c, aspect, box.center(), 0.5 * box.size().norm());
    Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d p(i & 1 ? box.max.x() : box.min.x(), i & 2 ? box.max.y() : box.min.y(),
                              i & 4 ? box.max.z() : box.min.z());
      const Eigen::Vector3d ndc = project(m, p);
      lo = lo.cwiseMin(ndc.head<2>()), hi = hi.cwiseMax(ndc.head<2>());
    }
    EXPECT_GE(lo.minCoeff(), -1.0 - 1e-9) << aspect;
    EXPECT_LE(hi.maxCoeff(), 1.0 + 1e-9) << aspect;
    const bool x_binds = hi.x() - lo.x() > hi.y() - lo.y();
    EXPECT_NEAR(x_binds ? lo.x() : lo.y(), -1.0, 1e-9) << aspect;
    EXPECT_NEAR(x_binds ? hi.x() : hi.y(), 1.0, 1e-9) << aspect;
    // The other axis centred.
    EXPECT_NEAR(x_binds ? lo.y() + hi.y() : lo.x() + hi.x(), 0.0, 1e-9) << aspect;
  }
}

TEST(Camera, TurntableFramingHoldsTheBoxFromEveryAngle) {
  const Aabb box = test_box();
  const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  const Camera c = frame_box(box, view_direction(View::Iso, up), up, 1.3, false, 35.0, 7, up);
  for (int k = 0; k < 7; ++k) {
    const Camera turned = orbit(c, up, 2.0 * std::numbers::pi * k / 7);
    EXPECT_NEAR((turned.eye - turned.target).norm(), (c.eye - c.target).norm(), 1e-12);
    EXPECT_LE(extent_in_view(turned, box, 1.3), 1.0) << k;
  }
}

TEST(Camera, MatricesMapTheTargetToTheImageCentre) {
  Camera c;
  c.eye = Eigen::Vector3d(1, 2, 3);
  c.target = Eigen::Vector3d(0.5, 0.0, -1.0);
  const ViewMatrices m = view_matrices(c, 1.5, c.target, 0.5);
  const Eigen::Vector3d ndc = project(m, c.target);
  EXPECT_NEAR(ndc.x(), 0.0, 1e-12);
  EXPECT_NEAR(ndc.y(), 0.0, 1e-12);
  // A point above the target along the image up lands in the upper half.
  EXPECT_GT(project(m, c.target + 0.1 * c.image_up()).y(), 0.0);
  EXPECT_GT(project(m, c.target + 0.1 * c.right()).x(), 0.0);
}

TEST(Camera, ValidationRejectsDegenerateCameras) {
  Camera c;
  EXPECT_NO_THROW(validate(c));
  Camera same = c;
  same.eye = same.target;
  EXPECT_THROW(validate(same), InputError);
  Camera parallel = c;
  parallel.up = parallel.target - parallel.eye;
  EXPECT_THROW(validate(parallel), InputError);
  Camera wide = c;
  wide.fov_y = 180.0;
  EXPECT_THROW(validate(wide), InputError);
  Camera flat = c;
  flat.ortho = true;
  flat.ortho_height = 0.0;
  EXPECT_THROW(validate(flat), InputError);
}

// Both renderers summarise --color-by through one helper: the pixels without surface (NaN) do not
// count, the others give count, mean and maximum.
TEST(PreviewFrame, ScalarSummaryCountsOnlyTheColouredSurfacePixels) {
  const double none = std::numeric_limits<double>::quiet_NaN();
  const ScalarSummary s = summarize_scalar({none, 0.5, 2.0, none, 0.5});
  EXPECT_EQ(s.pixels, 3u);
  EXPECT_DOUBLE_EQ(s.mean, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 2.0);
  const ScalarSummary empty = summarize_scalar({none, none});
  EXPECT_EQ(empty.pixels, 0u);
  EXPECT_EQ(empty.mean, 0.0);
}

}  // namespace
}  // namespace ts::preview
