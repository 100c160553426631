#pragma once
// The verdict `tetrasand sample` ends with: body OK, usable with caveats, or not usable, and why. A
// pure rule over a body's figures and its thin features, so it is tested without a GPU. The
// thresholds and the measurements they come from are in docs/body-format.md ("Verdict").
#include <string>
#include <vector>

#include "body/particle_body.h"
#include "sampler/thin_features.h"

namespace ts::sampler {

// The thresholds (docs/body-format.md, "Verdict", says why each is where it is).
struct VerdictThresholds {
  // Certified bound of the covering radius / r above which the body is not usable: grains smaller
  // than (bound - 1) r reach the mesh between the particles, here half a particle radius.
  double unusable_bound_over_r = 1.5;
  double min_relative_radius = 0.5;  // rho below: two particles closer than the thinning allows
  double max_cv = 0.1;               // CV above: less even than the Poisson-disk peer (0.09-0.096)
  double max_thin_share = 0.01;      // thin features on more of the surface area than this: a caveat
  double max_phi_over_r = 1e-3;      // particles farther from the mesh than this / r: a caveat
  double unusable_phi_over_r = 0.1;  // and this far: not usable (the body's surface is off by r / 10)
};

enum class Verdict { Ok, Caveats, NotUsable };

struct BodyVerdict {
  Verdict verdict = Verdict::Ok;
  // Worst first: every finding that is short of OK; for an OK body, the checks it passed.
  std::vector<std::string> reasons;
};

// "body OK", "usable with caveats" or "not usable".
const char* verdict_name(Verdict verdict);

// The body's figures (quality, mass properties, mass method) and its thin features, judged.
BodyVerdict judge_body(const body::ParticleBody& body, const ThinFeatures& thin,
                       const VerdictThresholds& thresholds = {});

}  // namespace ts::sampler
