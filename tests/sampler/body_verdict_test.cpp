// The verdict rule (sampler/body_verdict.h) branch by branch, on hand-made bodies: no GPU. The
// baseline body has the figures of a certified, converged sample (docs/benchmarks.md: sphere and
// bunny bodies); each test spoils one figure and checks the verdict and that the reason names it.
#include "sampler/body_verdict.h"

#include <gtest/gtest.h>

#include <string>

namespace ts::sampler {
namespace {

body::ParticleBody good_body() {
  body::ParticleBody b;
  b.positions.assign(100, Eigen::Vector3f::Zero());
  b.particle_radius = 0.01;
  b.mass = 1.0, b.volume = 1e-3;
  b.principal_moments = Eigen::Vector3d(1e-4, 1.2e-4, 1.5e-4);
  auto& q = b.quality;
  q.relative_radius = 0.8, q.cv = 0.037, q.covering_over_r = 0.95, q.max_abs_phi_over_r = 2e-6;
  q.converged = true, q.iterations = 260;
  q.certificate = body::ParticleBody::Quality::Certificate{true, 0.97, 0.95, 0, 0.0, 0.01 / 64};
  return b;
}

void uncertify(body::ParticleBody& b, double bound) {
  b.quality.certificate->certified = false;
  b.quality.certificate->bound_over_r = bound;
  b.quality.certificate->uncovered_subtriangles = 12;
}

// Thin features on `share` of the area in one region.
ThinFeatures thin_on(double share) {
  ThinFeatures t;
  t.triangles = 20;
  t.area_share = share;
  ThinRegion region;
  region.triangles = 20, region.area_share = share, region.thinnest = 0.007;
  region.resolving_radius = 0.0068, region.mostly_resolving_radius = 0.009;
  t.regions.push_back(region);
  return t;
}

bool mentions(const BodyVerdict& v, const std::string& text) {
  for (const auto& r : v.reasons)
    if (r.find(text) != std::string::npos) return true;
  return false;
}

std::string all_reasons(const BodyVerdict& v) {
  std::string out;
  for (const auto& r : v.reasons) out += r + " | ";
  return out;
}

// Judges `b` and checks the verdict and that one reason contains `text`.
void expect_judged(const body::ParticleBody& b, Verdict expected, const std::string& text,
                   const ThinFeatures& thin = {}) {
  const BodyVerdict v = judge_body(b, thin);
  EXPECT_EQ(v.verdict, expected) << all_reasons(v);
  EXPECT_TRUE(mentions(v, text)) << "'" << text << "' not in: " << all_reasons(v);
}

TEST(BodyVerdict, ACertifiedConvergedEvenBodyIsOkAndListsTheChecksItPassed) {
  const BodyVerdict v = judge_body(good_body(), ThinFeatures{});
  EXPECT_EQ(v.verdict, Verdict::Ok) << all_reasons(v);
  EXPECT_TRUE(mentions(v, "coverage certified (covering radius <= 0.970 r)")) << all_reasons(v);
  EXPECT_TRUE(mentions(v, "relaxation converged")) << all_reasons(v);
  EXPECT_TRUE(mentions(v, "no thin features")) << all_reasons(v);
  EXPECT_STREQ(verdict_name(v.verdict), "body OK");
}

TEST(BodyVerdict, AnUncertifiedBoundSlightlyAboveOneIsACaveatNamingTheGrainsThatLeak) {
  body::ParticleBody b = good_body();
  uncertify(b, 1.1);
  expect_judged(b, Verdict::Caveats, "coverage NOT certified: covering radius <= 1.100 r");
  expect_judged(b, Verdict::Caveats, "grains smaller than 0.10 r");
  EXPECT_STREQ(verdict_name(Verdict::Caveats), "usable with caveats");
}

TEST(BodyVerdict, AnUncertifiedBoundWellAboveOneIsNotUsable) {
  body::ParticleBody b = good_body();
  uncertify(b, 1.5);  // at the threshold: still a caveat
  EXPECT_EQ(judge_body(b, ThinFeatures{}).verdict, Verdict::Caveats);
  uncertify(b, 1.6);
  expect_judged(b, Verdict::NotUsable, "above 1.5 r");
  EXPECT_STREQ(verdict_name(Verdict::NotUsable), "not usable");
}

TEST(BodyVerdict, ABodyWithoutACertificateIsJudgedByItsProbesAndNeverOk) {
  body::ParticleBody b = good_body();
  b.quality.certificate.reset();
  expect_judged(b, Verdict::Caveats, "no coverage certificate: probes found covering radius 0.950 r");
  b.quality.covering_over_r = 1.7;
  expect_judged(b, Verdict::NotUsable, "no coverage certificate: probes found covering radius 1.700 r");
}

TEST(BodyVerdict, AnUnconvergedRelaxationIsACaveat) {
  body::ParticleBody b = good_body();
  b.quality.converged = false;
  b.quality.iterations = 50;
  expect_judged(b, Verdict::Caveats, "relaxation NOT converged after 50 iterations");
}

TEST(BodyVerdict, UnevenSpacingIsACaveatByRhoOrByCv) {
  body::ParticleBody b = good_body();
  b.quality.relative_radius = 0.45;
  expect_judged(b, Verdict::Caveats, "uneven spacing: rho 0.450");
  b = good_body();
  b.quality.cv = 0.12;
  expect_judged(b, Verdict::Caveats, "CV 0.120");
  b.quality.relative_radius = 0.5, b.quality.cv = 0.1;  // at both thresholds: even
  EXPECT_EQ(judge_body(b, ThinFeatures{}).verdict, Verdict::Ok);
}

TEST(BodyVerdict, ThinFeaturesOnMoreThanOnePercentOfTheAreaAreACaveatWithTheRadiusThatResolvesThem) {
  const body::ParticleBody b = good_body();
  expect_judged(b, Verdict::Caveats, "thin features on 30.00 % of the area in 1 region", thin_on(0.3));
  expect_judged(
      b, Verdict::Caveats,
      "the largest (30.00 % of the area): --radius 0.009 resolves 90 % of it, --radius 0.0068 all of it "
      "(now 0.01)",
      thin_on(0.3));
  // The bunny's ear tips at 4,000 particles: named, not a caveat.
  expect_judged(b, Verdict::Ok, "thin features on 0.45 % of the area in 1 region only", thin_on(0.0045));
}

TEST(BodyVerdict, ParticlesOffTheMeshAreACaveatThenNotUsable) {
  body::ParticleBody b = good_body();
  b.quality.max_abs_phi_over_r = 0.01;
  expect_judged(b, Verdict::Caveats, "some particles are off the mesh");
  b.quality.max_abs_phi_over_r = 0.2;
  expect_judged(b, Verdict::NotUsable, "the particles are off the mesh");
}

TEST(BodyVerdict, InvalidMassPropertiesAreNotUsable) {
  body::ParticleBody b = good_body();
  b.mass = 0.0;
  expect_judged(b, Verdict::NotUsable, "mass properties invalid");
  b = good_body();
  b.principal_moments = Eigen::Vector3d(1e-4, 1e-4, 3e-4);  // no mass distribution has these
  expect_judged(b, Verdict::NotUsable, "mass properties invalid");
}

TEST(BodyVerdict, AnOpenMeshSampledByWindingNumberIsACaveat) {
  body::ParticleBody b = good_body();
  b.mass_method = body::MassMethod::WindingCells;
  expect_judged(b, Verdict::Caveats, "holes are not covered");
}

TEST(BodyVerdict, ReasonsListEveryShortcomingWorstFirstAndNoPassedCheck) {
  body::ParticleBody b = good_body();
  b.quality.converged = false;  // a caveat
  uncertify(b, 2.0);            // not usable
  const BodyVerdict v = judge_body(b, ThinFeatures{});
  EXPECT_EQ(v.verdict, Verdict::NotUsable);
  ASSERT_EQ(v.reasons.size(), 2u) << all_reasons(v);
  EXPECT_NE(v.reasons[0].find("coverage NOT certified"), std::string::npos) << all_reasons(v);
  EXPECT_NE(v.reasons[1].find("NOT converged"), std::string::npos) << all_reasons(v);
}

}  // namespace
}  // namespace ts::sampler
