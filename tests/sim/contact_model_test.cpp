#include "sim/contact_model.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ts::sim {
namespace {

ContactCoefficients<double> coefficients(double restitution, NormalDamping damping) {
  Material m;
  m.restitution = restitution;
  return ContactCoefficients<double>::from(make_pair_coefficients(m, m, damping), damping);
}

TEST(ContactModel, UndampedScaledImpactLastsHertzDuration) {
  const ScaledImpact impact = scaled_hertz_impact(0.0, 0.25);
  EXPECT_NEAR(impact.restitution, 1.0, 1e-4);
  EXPECT_NEAR(impact.duration, 3.21, 0.01);  // eq. 3.22 in units of (m*/k_n)^(2/5) v^(-1/5)
}

TEST(ContactModel, CalibratedDampingReproducesRequestedRestitution) {
  for (double e : {0.1, 0.3, 0.65, 0.9, 0.99}) {
    for (double exponent : {0.25, 0.5}) {
      const double c = damping_strength_for_restitution(e, exponent);
      EXPECT_NEAR(scaled_hertz_impact(c, exponent).restitution, e, 1e-4) << "e " << e << " p " << exponent;
    }
  }
}

TEST(ContactModel, TsujiDampingIsStrongerThanLammpsBetaBecauseTheForceIsClamped) {
  // Without the clamp, beta = ln e / sqrt(ln^2 e + pi^2) is exact; clamping the attractive tail off
  // needs more damping for the same rebound.
  const double e = 0.65;
  const double beta = std::log(e) / std::sqrt(std::log(e) * std::log(e) + M_PI * M_PI);
  const double c = damping_strength_for_restitution(e, 0.25);
  EXPECT_GT(c, -std::sqrt(5.0) * beta);
  EXPECT_GT(scaled_hertz_impact(-std::sqrt(5.0) * beta, 0.25).restitution, e + 0.02);
}

TEST(ContactModel, SeparatedSpheresFeelNoForce) {
  const auto c = coefficients(0.65, NormalDamping::Tsuji);
  const Vec3<double> zero = Vec3<double>::Zero();
  const auto f = sphere_sphere_contact<double>(Vec3<double>(0.0021, 0, 0), zero, zero, 1e-3, 1.0, zero, zero, zero,
                                               1e-3, 1.0, 1.0, c);
  EXPECT_FALSE(f.touching);
  EXPECT_EQ(f.force, zero);
}

TEST(ContactModel, StaticOverlapGivesHertzForce) {
  const auto c = coefficients(0.65, NormalDamping::Tsuji);
  const Vec3<double> zero = Vec3<double>::Zero();
  const double r = 1e-3, delta = 1e-5;
  const auto f = sphere_sphere_contact<double>(Vec3<double>(2 * r - delta, 0, 0), zero, zero, r, 1.0, zero, zero,
                                               zero, r, 1.0, 1.0, c);
  const double expected = 4.0 / 3.0 * c.effective_modulus * std::sqrt(r / 2) * std::pow(delta, 1.5);
  EXPECT_NEAR(f.force.x(), expected, 1e-9 * expected);
  EXPECT_NEAR(f.force.y(), 0.0, 1e-15);
  EXPECT_TRUE((f.arm - Vec3<double>(-(r - delta / 2), 0, 0)).norm() < 1e-15);
}

TEST(ContactModel, NormalForceNeverAttracts) {
  for (auto damping : {NormalDamping::Tsuji, NormalDamping::Thesis}) {
    const auto c = coefficients(0.1, damping);
    const Vec3<double> zero = Vec3<double>::Zero();
    // Small overlap, separating fast: the damping term alone would pull the spheres together.
    const auto f = sphere_sphere_contact<double>(Vec3<double>(2e-3 - 1e-8, 0, 0), Vec3<double>(5, 0, 0), zero, 1e-3,
                                                 1e5, zero, zero, zero, 1e-3, 1e5, 1.0, c);
    EXPECT_TRUE(f.touching);
    EXPECT_GE(f.force.x(), 0.0);
  }
}

TEST(ContactModel, TangentialForceIsViscousBelowTheCoulombCap) {
  Material m;
  m.friction = 0.5;
  m.tangential_damping = 10.0;
  const auto c = ContactCoefficients<double>::from(make_pair_coefficients(m, m, NormalDamping::Tsuji),
                                                   NormalDamping::Tsuji);
  const Vec3<double> zero = Vec3<double>::Zero(), n = Vec3<double>::UnitZ();
  const double r = 1e-3, delta = 1e-5;
  const double normal = 4.0 / 3.0 * c.effective_modulus * std::sqrt(r) * std::pow(delta, 1.5);
  // Slow slip: gamma_s |v_s|.
  const double slow = 0.1 * c.friction * normal / c.tangential_damping;
  auto f = sphere_wall_contact<double>(n, r - delta, Vec3<double>(slow, 0, 0), zero, r, 1.0, 1.0, c);
  EXPECT_NEAR(f.force.x(), -c.tangential_damping * slow, 1e-9 * normal);
  EXPECT_NEAR(f.force.z(), normal, 1e-9 * normal);
  // Fast slip: capped at mu F_n.
  f = sphere_wall_contact<double>(n, r - delta, Vec3<double>(100 * slow, 0, 0), zero, r, 1.0, 1.0, c);
  EXPECT_NEAR(f.force.x(), -c.friction * normal, 1e-9 * normal);
}

TEST(ContactModel, PairForceIsExactlyAntisymmetric) {
  const auto c = coefficients(0.65, NormalDamping::Thesis);
  const Vec3<double> p1(0.1, 0.2, 0.3), p2(0.1015, 0.2003, 0.2996);
  const Vec3<double> v1(0.3, -0.2, 0.1), v2(-0.1, 0.4, 0.0), w1(3, 1, -2), w2(-1, 5, 2);
  const auto a = sphere_sphere_contact<double>(p1, v1, w1, 1e-3, 2e4, p2, v2, w2, 0.8e-3, 3e4, 1.0, c);
  const auto b = sphere_sphere_contact<double>(p2, v2, w2, 0.8e-3, 3e4, p1, v1, w1, 1e-3, 2e4, 1.0, c);
  ASSERT_TRUE(a.touching);
  EXPECT_EQ(a.force, -b.force);
  EXPECT_LT(((p1 + a.arm) - (p2 + b.arm)).norm(), 1e-15);  // same point of application
}

TEST(ContactModel, FloatAndDoubleAgree) {
  const auto cd = coefficients(0.65, NormalDamping::Tsuji);
  ContactCoefficients<float> cf{float(cd.effective_modulus), float(cd.friction), float(cd.tangential_damping),
                                float(cd.damping_strength), float(cd.thesis_reference_speed), cd.damping};
  const auto d = sphere_wall_contact<double>(Vec3<double>::UnitZ(), 0.99e-3, Vec3<double>(0.1, 0, -0.5),
                                             Vec3<double>(0, 2, 0), 1e-3, 1e5, 1.0, cd);
  const auto f = sphere_wall_contact<float>(Vec3<float>::UnitZ(), 0.99e-3f, Vec3<float>(0.1f, 0, -0.5f),
                                            Vec3<float>(0, 2, 0), 1e-3f, 1e5f, 1.0f, cf);
  EXPECT_LT((d.force.cast<float>() - f.force).norm(), 1e-4f * d.force.cast<float>().norm());
}

TEST(MaterialValidation, RejectsNonPhysicalValues) {
  Material m;
  EXPECT_EQ(validate(m), "");
  m.youngs_modulus = -1;
  EXPECT_NE(validate(m).find("E:"), std::string::npos);
  m = Material{};
  m.poisson_ratio = 0.5;
  EXPECT_NE(validate(m).find("nu:"), std::string::npos);
  m = Material{};
  m.restitution = 1.2;
  EXPECT_NE(validate(m).find("restitution"), std::string::npos);
}

}  // namespace
}  // namespace ts::sim
