// The up convention's hint (core/up_axis.h): which axis a mesh is tallest along, when that is no
// guide, and the advice `info` prints.
#include "core/up_axis.h"

#include <gtest/gtest.h>

namespace ts {
namespace {

Aabb box_of(double x, double y, double z) {
  Aabb b;
  b.extend(Eigen::Vector3d::Zero());
  b.extend(Eigen::Vector3d(x, y, z));
  return b;
}

TEST(UpAxis, ATallBoxStandsOnZAndNeedsNoChoice) {
  const UpAxisHint h = up_axis_hint(box_of(1, 2, 4));
  EXPECT_EQ(h.tallest, 2);
  EXPECT_EQ(h.runner_up, 1);
  EXPECT_FALSE(h.ambiguous);
  EXPECT_NE(up_axis_advice(h, "m.obj").find("nothing to choose"), std::string::npos);
}

TEST(UpAxis, AMeshTallestAlongYGetsTheUpOptionAndTheSceneOrientation) {
  const UpAxisHint h = up_axis_hint(box_of(1, 4, 2));
  EXPECT_EQ(h.tallest, 1);
  EXPECT_FALSE(h.ambiguous);
  const std::string advice = up_axis_advice(h, "m.obj");
  EXPECT_NE(advice.find("--up 0,1,0"), std::string::npos) << advice;
  EXPECT_NE(advice.find("orientation = [0.7071068, 0.7071068, 0, 0]"), std::string::npos) << advice;
  // The orientation named for x really takes +x onto +z.
  const Eigen::Quaterniond onto_z(0.7071068, 0, -0.7071068, 0);
  EXPECT_NEAR((onto_z.normalized() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-6);
  EXPECT_NE(up_axis_advice(up_axis_hint(box_of(4, 1, 2)), "m.obj").find("[0.7071068, 0, -0.7071068, 0]"),
            std::string::npos);
  const Eigen::Quaterniond y_onto_z(0.7071068, 0.7071068, 0, 0);
  EXPECT_NEAR((y_onto_z.normalized() * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-6);
}

TEST(UpAxis, NearlyEqualExtentsAreAmbiguousAndTheAdviceSaysHowToLook) {
  // CGAL's dino: 2.0 x 3.7 x 4.06 m, z tallest but y within 9 %.
  const UpAxisHint h = up_axis_hint(box_of(1.99, 3.70, 4.06));
  EXPECT_EQ(h.tallest, 2);
  EXPECT_EQ(h.runner_up, 1);
  EXPECT_TRUE(h.ambiguous);
  const std::string advice = up_axis_advice(h, "dino.off");
  EXPECT_NE(advice.find("ambiguous"), std::string::npos) << advice;
  EXPECT_NE(advice.find("z, y extents"), std::string::npos) << advice;
  EXPECT_NE(advice.find("`tetrasand preview dino.off` and `-o up_z.png --up 0,0,1`, `-o up_y.png --up 0,1,0`,"),
            std::string::npos)
      << advice;
  EXPECT_EQ(advice.find("up_x"), std::string::npos) << advice;  // x is half as long: not a candidate
  EXPECT_NE(up_axis_advice(up_axis_hint(box_of(1, 1, 1)), "c.obj").find("z, y, x extents"), std::string::npos);
  EXPECT_FALSE(up_axis_hint(box_of(1, 3.3, 4)).ambiguous);  // 82 %: z it is
}

TEST(UpAxis, TiesAndEmptyBoxesGoToTheConvention) {
  EXPECT_EQ(up_axis_hint(box_of(1, 1, 1)).tallest, 2);
  EXPECT_EQ(up_axis_hint(Aabb{}).tallest, 2);
  EXPECT_FALSE(up_axis_hint(Aabb{}).ambiguous);
}

}  // namespace
}  // namespace ts
