// Thin features named by region (sampler/thin_features.h), on the CPU: a 20 cm cube with two 4 mm
// plates beside it, at a spacing whose thin threshold (0.75 spacing = 15 mm) lies between the two
// thicknesses. Each plate must come out as one region with its own bounding box, its share of the
// area, its thickness and the radius that resolves it; the cube not at all.
#include "sampler/thin_features.h"

#include <gtest/gtest.h>

#include "core/primitives.h"
#include "tests/test_meshes.h"

namespace ts::sampler {
namespace {

constexpr double kPlate = 0.004;    // m, thickness of both plates
constexpr double kSpacing = 0.02;   // m
constexpr double kRadius = 0.0144;  // m (the sampler's radius for that spacing, about spacing / 1.386)

struct Scene {
  TriangleMesh mesh, large, small;  // large and small: the plates, as placed
};

Scene cube_with_two_plates() {
  Scene s;
  s.mesh = make_box(Eigen::Vector3d(0.2, 0.2, 0.2));
  s.large = make_plate(0.3, 0.3, kPlate, 6, 6);
  s.small = make_plate(0.1, 0.1, kPlate, 2, 2);
  test::append_shell(s.mesh, s.large, Eigen::Vector3d(0.5, 0.0, 0.0));
  test::append_shell(s.mesh, s.small, Eigen::Vector3d(-0.5, 0.0, 0.0));
  for (auto& v : s.large.vertices) v += Eigen::Vector3d(0.5, 0.0, 0.0);
  for (auto& v : s.small.vertices) v += Eigen::Vector3d(-0.5, 0.0, 0.0);
  return s;
}

void expect_region_is_plate(const ThinRegion& region, const TriangleMesh& plate, double total_area) {
  const Aabb box = bounding_box(plate);
  EXPECT_LE((region.box.min - box.min).norm(), 1e-12);
  EXPECT_LE((region.box.max - box.max).norm(), 1e-12);
  EXPECT_EQ(region.triangles, plate.triangle_count());
  EXPECT_NEAR(region.area_share, surface_area(plate) / total_area, 1e-12);
  // The plate's thickness, on its faces and on its rim alike (the search keeps the passing side).
  EXPECT_LE(region.thinnest, kPlate + 1e-9);
  EXPECT_GE(region.thinnest, kPlate - 1e-6);
  // At the resolving radius the spacing scales by resolving / r, and 0.75 of it is the thickness
  // (less the margin).
  EXPECT_NEAR(kThinOverSpacing * kSpacing * region.resolving_radius / kRadius,
              kResolvingMargin * region.thinnest, 1e-12);
  EXPECT_NEAR(region.mostly_resolving_radius, region.resolving_radius, 1e-6);  // one thickness throughout
}

TEST(ThinFeatures, EachThinPlateIsOneRegionWithItsBoxShareAndResolvingRadius) {
  const Scene s = cube_with_two_plates();
  const sdf::ExactDistance exact(s.mesh);
  const ThinFeatures thin = find_thin_features(s.mesh, exact, kSpacing, kRadius);
  const double total = surface_area(s.mesh);
  ASSERT_EQ(thin.regions.size(), 2u);
  EXPECT_EQ(thin.triangles, s.large.triangle_count() + s.small.triangle_count());  // none of the cube's
  EXPECT_NEAR(thin.threshold, kThinOverSpacing * kSpacing, 1e-15);
  EXPECT_NEAR(thin.area_share, (surface_area(s.large) + surface_area(s.small)) / total, 1e-12);
  expect_region_is_plate(thin.regions[0], s.large, total);  // largest area first
  expect_region_is_plate(thin.regions[1], s.small, total);
}

TEST(ThinFeatures, ASpacingTheThicknessResolvesFindsNone) {
  const Scene s = cube_with_two_plates();
  const sdf::ExactDistance exact(s.mesh);
  // A spacing whose 0.75 lies below the plates' thickness.
  const ThinFeatures thin = find_thin_features(s.mesh, exact, 0.9 * kPlate / kThinOverSpacing, kRadius);
  EXPECT_EQ(thin.triangles, 0u);
  EXPECT_TRUE(thin.regions.empty());
  EXPECT_EQ(thin.area_share, 0.0);
}

// A region whose tip tapers (a claw) gets two radii; one no radius resolves says so.
TEST(ThinFeatures, TheSuggestionNamesTheRadiusForMostOfARegionAndForAllOfIt) {
  ThinRegion region;
  region.resolving_radius = region.mostly_resolving_radius = 0.002;
  EXPECT_EQ(resolving_radii_text(region), "--radius 0.002 resolves all of it");
  region.mostly_resolving_radius = 0.02;
  EXPECT_EQ(resolving_radii_text(region), "--radius 0.02 resolves 90 % of it, --radius 0.002 all of it");
  region.resolving_radius = 0.0;
  EXPECT_EQ(resolving_radii_text(region),
            "--radius 0.02 resolves 90 % of it, no radius all of it (a knife edge or a sliver)");
  region.mostly_resolving_radius = 0.0;
  EXPECT_EQ(resolving_radii_text(region), "no radius resolves it (a knife edge or a sliver)");
}

}  // namespace
}  // namespace ts::sampler
