// The parallel-bond law and the bonds of a body (sim/bond_model.h, sim/bonds.h): criteria 1 and 2 of
// docs/validation.md "Bonded particles" at the level of one pair, and the bookkeeping of many.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>

#include "sim/bond_model.h"
#include "sim/bonds.h"

namespace ts::sim {
namespace {

using V = Eigen::Vector3d;

constexpr double kRadius = 1e-3;  // m

BondMaterial cement() {
  BondMaterial m;
  m.youngs_modulus = 1e8;
  m.tensile_strength = 5e6;
  m.shear_strength = 8e6;
  return m;
}

// Sphere b at the origin, sphere a touching it on +x (n = +x), both at rest unless the test moves them.
struct Pair {
  V p_a = V(2 * kRadius, 0, 0), p_b = V::Zero();
  V v_a = V::Zero(), v_b = V::Zero(), w_a = V::Zero(), w_b = V::Zero();
  BondGeometry<double> g = bond_geometry(kRadius, kRadius, cement());
  BondState<double> state;

  BondLoad<double> step(double dt, double tensile = 1e30, double shear = 1e30) {
    const BondLoad<double> load = bond_interaction(p_a, v_a, w_a, kRadius, p_b, v_b, w_b, kRadius, g, tensile,
                                                   shear, dt, state);
    p_a += v_a * dt;
    p_b += v_b * dt;
    return load;
  }
};

TEST(BondModel, StretchedBondHoldsTheLinearSpringForce) {
  Pair pair;
  pair.v_a = V(1e-3, 0, 0);  // a moves away from b
  const double dt = 1e-6;
  for (int k = 0; k < 100; ++k) pair.step(dt);
  const double stretch = 100 * 1e-3 * dt;
  const double expected = -pair.g.normal_stiffness * pair.g.area * stretch;  // tension pulls a back
  EXPECT_NEAR(pair.state.normal_force, expected, 1e-12 * std::abs(expected));
  EXPECT_NEAR(bond_stresses(pair.state, pair.g).tensile, pair.g.normal_stiffness * stretch,
              1e-12 * pair.g.normal_stiffness * stretch);
}

TEST(BondModel, TwistedAndBentBondsHoldTheirMoments) {
  Pair pair;
  const double dt = 1e-6, rate = 0.5;  // rad/s
  pair.w_a = V(rate, 0, 0);            // twist about n = +x
  for (int k = 0; k < 200; ++k) pair.step(dt);
  const double angle = 200 * rate * dt;
  const double twist = -pair.g.shear_stiffness * pair.g.polar_inertia * angle;
  EXPECT_NEAR(pair.state.twisting_moment, twist, 1e-12 * std::abs(twist));

  Pair bent;
  bent.w_a = V(0, 0, rate);  // bend about z: a turns, b does not
  bent.w_b = V(0, 0, -rate);
  for (int k = 0; k < 200; ++k) bent.step(dt);
  // The centres stay put and the two surface points at the bond move together: a pure bend, no shear.
  EXPECT_EQ(bent.state.shear_force.norm(), 0.0);
  const double bending = -bent.g.normal_stiffness * bent.g.bending_inertia * 2 * angle;
  EXPECT_NEAR(bent.state.bending_moment.z(), bending, 1e-12 * std::abs(bending));
  EXPECT_NEAR(bent.state.bending_moment.head<2>().norm(), 0.0, 1e-15);
}

TEST(BondModel, BondBreaksInTheFirstStepItsStressPassesTheStrength) {
  Pair pair;
  pair.v_a = V(1e-3, 0, 0);
  const double dt = 1e-6, strength = 3.001e4;  // Pa, off a whole number of steps' stress
  const double per_step = pair.g.normal_stiffness * 1e-3 * dt;
  const int first = static_cast<int>(std::floor(strength / per_step)) + 1;
  for (int k = 1; k < first; ++k) ASSERT_FALSE(pair.step(dt, strength).broke) << "step " << k;
  const BondLoad<double> load = pair.step(dt, strength);
  EXPECT_TRUE(load.broke);
  EXPECT_EQ(load.force, V::Zero());
  EXPECT_EQ(pair.state.normal_force, 0.0);
}

TEST(BondModel, ShearAndTwistBreakAgainstTheShearStrength) {
  Pair pair;
  pair.v_a = V(0, 1e-3, 0);  // slide a past b
  const double dt = 1e-6;
  bool broke = false;
  int steps = 0;
  while (!broke && steps < 100000) broke = pair.step(dt, 1e30, 1e4).broke, ++steps;
  ASSERT_TRUE(broke);
  EXPECT_LT(steps, 100000);
}

TEST(BondModel, RigidMotionOfThePairLoadsNothing) {
  Pair pair;
  const V w(0.3, -0.7, 2.0);  // rad/s, about the pair's midpoint
  const double dt = 1e-5;
  for (int k = 0; k < 2000; ++k) {
    const V mid = 0.5 * (pair.p_a + pair.p_b);
    pair.w_a = pair.w_b = w;
    pair.v_a = w.cross(pair.p_a - mid) + V(0.1, 0, 0);
    pair.v_b = w.cross(pair.p_b - mid) + V(0.1, 0, 0);
    pair.step(dt);
  }
  // Explicit positions drift outwards by O(w^2 dt^2) a step: a load of that order is all that may build.
  const BondStresses<double> s = bond_stresses(pair.state, pair.g);
  EXPECT_LT(std::abs(s.tensile), 1e-6 * cement().tensile_strength);
  EXPECT_LT(std::abs(s.shear), 1e-6 * cement().shear_strength);
}

// Two free spheres joined by one bond, integrated by symplectic Euler as the steppers do.
struct FreePair {
  double mass = 1000.0 * 4.0 / 3.0 * 3.14159265358979323846 * kRadius * kRadius * kRadius;
  double inertia = 0.4 * mass * kRadius * kRadius;
  Pair pair;

  double kinetic(const V& v_a, const V& v_b, const V& w_a, const V& w_b) const {
    return 0.5 * mass * (v_a.squaredNorm() + v_b.squaredNorm()) + 0.5 * inertia * (w_a.squaredNorm() + w_b.squaredNorm());
  }
};

TEST(BondModel, BondedPairKeepsItsEnergyWithoutDampingAtTheBondTimeStep) {
  FreePair free;
  Pair& p = free.pair;
  p.v_a = V(2e-4, 1e-4, -5e-5);
  p.v_b = -p.v_a;
  p.w_a = V(0.05, 0.2, -0.1);
  p.w_b = V(-0.02, 0.1, 0.15);
  const BondSet bonds = build_bonds({p.p_a, p.p_b}, {kRadius, kRadius}, cement(), 1);
  const double dt = bond_time_step(bonds, {free.mass, free.mass}, {kRadius, kRadius}, cement());
  ASSERT_EQ(bonds.size(), 1u);
  ASSERT_TRUE(std::isfinite(dt));
  double first = 0.0, largest_error = 0.0;
  for (int k = 0; k < 10000; ++k) {
    const V v_a = p.v_a, v_b = p.v_b, w_a = p.w_a, w_b = p.w_b;
    const BondLoad<double> load = bond_interaction(p.p_a, p.v_a, p.w_a, kRadius, p.p_b, p.v_b, p.w_b, kRadius, p.g,
                                                   1e30, 1e30, dt, p.state);
    p.v_a += load.force / free.mass * dt;
    p.v_b -= load.force / free.mass * dt;
    p.w_a += (load.arm_a.cross(load.force) + load.moment) / free.inertia * dt;
    p.w_b += (load.arm_b.cross(-load.force) - load.moment) / free.inertia * dt;
    p.p_a += p.v_a * dt;
    p.p_b += p.v_b * dt;
    const double energy = free.kinetic(0.5 * (v_a + p.v_a), 0.5 * (v_b + p.v_b), 0.5 * (w_a + p.w_a),
                                       0.5 * (w_b + p.w_b)) +
                          bond_energy(p.state, p.g);
    if (k == 0) first = energy;
    largest_error = std::max(largest_error, std::abs(energy / first - 1.0));
  }
  std::printf("bonded pair: largest energy error %.3g over 10^4 steps at dt = %.3g s\n", largest_error, dt);
  EXPECT_LT(largest_error, 0.005) << "criterion 2: 0.5 % over 10^4 steps";
}

// An FCC lattice of spacing 2 r, n x n x n cubic cells (4 points a cell).
std::vector<V> fcc_block(int n, double r) {
  const double a = 2.0 * std::sqrt(2.0) * r;  // cube edge for nearest neighbours at 2 r
  const V basis[4] = {V(0, 0, 0), V(0.5, 0.5, 0), V(0.5, 0, 0.5), V(0, 0.5, 0.5)};
  std::vector<V> points;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (const V& b : basis) points.push_back(a * (V(x, y, z) + b));
  return points;
}

TEST(Bonds, FillLatticeNeighboursAreBondedOnceInAscendingOrder) {
  const std::vector<V> points = fcc_block(4, kRadius);
  const std::vector<double> radii(points.size(), kRadius);
  const BondSet bonds = build_bonds(points, radii, cement(), 7);
  std::set<std::pair<std::uint32_t, std::uint32_t>> expected;
  for (std::uint32_t i = 0; i < points.size(); ++i)
    for (std::uint32_t j = i + 1; j < points.size(); ++j)
      if ((points[i] - points[j]).norm() < 1.2 * 2 * kRadius) expected.emplace(i, j);
  ASSERT_EQ(bonds.size(), expected.size());
  std::size_t k = 0;
  for (const auto& [i, j] : expected) {
    EXPECT_EQ(bonds.a[k], i);
    EXPECT_EQ(bonds.b[k], j);
    ++k;
  }
  EXPECT_EQ(bonds.intact_count(), bonds.size());
  std::map<std::uint32_t, int> degree;
  for (std::size_t b = 0; b < bonds.size(); ++b) ++degree[bonds.a[b]], ++degree[bonds.b[b]];
  int largest = 0;
  for (const auto& [_, d] : degree) largest = std::max(largest, d);
  EXPECT_EQ(largest, 12);  // an interior FCC point's nearest neighbours
}

TEST(Bonds, StrengthsFollowTheSpreadAndDependOnlyOnSeedAndSpheres) {
  const std::vector<V> points = fcc_block(6, kRadius);
  const std::vector<double> radii(points.size(), kRadius);
  BondMaterial uniform = cement();
  const BondSet same = build_bonds(points, radii, uniform, 3);
  for (double s : same.tensile_strength) ASSERT_EQ(s, uniform.tensile_strength);

  BondMaterial spread = cement();
  spread.strength_spread = 0.3;
  const BondSet a = build_bonds(points, radii, spread, 3);
  const BondSet again = build_bonds(points, radii, spread, 3);
  const BondSet other = build_bonds(points, radii, spread, 4);
  EXPECT_EQ(a.tensile_strength, again.tensile_strength);
  EXPECT_NE(a.tensile_strength, other.tensile_strength);
  double sum = 0, sum2 = 0;
  for (double s : a.tensile_strength) {
    const double f = s / spread.tensile_strength;
    EXPECT_GE(f, kMinStrengthFactor);
    sum += f, sum2 += f * f;
  }
  const double n = static_cast<double>(a.size());
  ASSERT_GT(n, 2000);
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 1.0, 0.03);  // 5 standard errors of the mean for 2,000+ draws
  EXPECT_NEAR(sd, 0.3, 0.03);
}

TEST(Bonds, SphereMassesKeepTheBodysMassAndCentreOfMassToRoundOff) {
  std::vector<V> points = fcc_block(3, kRadius);
  std::vector<bool> interior(points.size(), true);
  for (std::size_t i = 0; i < points.size(); i += 5) interior[i] = false;
  BodyMassShare body;
  body.volume = 4.0 * std::sqrt(2.0) * std::pow(kRadius, 3) * points.size() * 1.1;
  body.mass = 2600.0 * body.volume;
  V centre = V::Zero();
  for (const V& p : points) centre += p;
  body.centre_of_mass = centre / points.size() + V(1e-4, -2e-4, 5e-5);  // off the spheres' own centre
  const std::vector<double> masses = sphere_masses(points, std::vector<double>(points.size(), kRadius), interior, body);
  double total = 0;
  V moment = V::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) total += masses[i], moment += masses[i] * points[i];
  EXPECT_NEAR(total, body.mass, 1e-12 * body.mass);
  EXPECT_LT((moment / total - body.centre_of_mass).norm(), 1e-12 * 10 * kRadius);
}

TEST(Bonds, SpheresInAPlaneTheCentreOfMassIsOffAreRefused) {
  std::vector<V> points;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) points.emplace_back(2 * kRadius * i, 2 * kRadius * j, 0.0);
  BodyMassShare body{1e-3, 1e-7, V(4 * kRadius, 4 * kRadius, kRadius)};
  EXPECT_THROW(sphere_masses(points, std::vector<double>(points.size(), kRadius),
                             std::vector<bool>(points.size(), true), body),
               std::invalid_argument);
  body.centre_of_mass.z() = 0.0;  // in the plane: reachable
  EXPECT_NO_THROW(sphere_masses(points, std::vector<double>(points.size(), kRadius),
                                std::vector<bool>(points.size(), true), body));
}

TEST(Bonds, BondMaterialProblemsNameTheKey) {
  EXPECT_EQ(validate(cement()), "");
  BondMaterial m = cement();
  m.tensile_strength = 0;
  EXPECT_NE(validate(m).find("tensile_strength"), std::string::npos);
  m = cement();
  m.bond_distance = 0.9;
  EXPECT_NE(validate(m).find("bond_distance"), std::string::npos);
  m = cement();
  m.radius_factor = 1.5;
  EXPECT_NE(validate(m).find("radius_factor"), std::string::npos);
}

TEST(Bonds, StifferBondsShortenTheTimeStepAsTheSquareRoot) {
  const std::vector<V> points = fcc_block(2, kRadius);
  const std::vector<double> radii(points.size(), kRadius);
  const std::vector<double> masses(points.size(), 1e-5);
  BondMaterial soft = cement(), stiff = cement();
  stiff.youngs_modulus = 100 * soft.youngs_modulus;
  const double dt_soft = bond_time_step(build_bonds(points, radii, soft, 1), masses, radii, soft);
  const double dt_stiff = bond_time_step(build_bonds(points, radii, stiff, 1), masses, radii, stiff);
  EXPECT_NEAR(dt_soft / dt_stiff, 10.0, 1e-9);
  EXPECT_TRUE(std::isinf(bond_time_step(BondSet{}, {}, {}, soft)));
}

}  // namespace
}  // namespace ts::sim
