#include "sampler/body_verdict.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace ts::sampler {
namespace {

struct Finding {
  Verdict verdict = Verdict::Ok;
  std::string text;
};

using Findings = std::vector<Finding>;

bool positive_finite(double x) { return std::isfinite(x) && x > 0.0; }

// Mass, volume and principal moments a rigid body can have: positive, finite, and each moment at most
// the sum of the other two (true of every real mass distribution).
void judge_mass_properties(const body::ParticleBody& b, Findings& out) {
  const Eigen::Vector3d& m = b.principal_moments;
  const bool moments = positive_finite(m.minCoeff()) && std::isfinite(m.maxCoeff()) &&
                       m.maxCoeff() <= (m.sum() - m.maxCoeff()) * (1.0 + 1e-9);
  if (!positive_finite(b.mass) || !positive_finite(b.volume) || !b.center_of_mass.allFinite() || !moments) {
    out.push_back(
        {Verdict::NotUsable,
         fmt::format("mass properties invalid (mass {:.4g} kg, volume {:.4g} m^3, principal moments "
                     "{:.4g} {:.4g} {:.4g} kg m^2): is the mesh inside out or not a solid?",
                     b.mass, b.volume, m.x(), m.y(), m.z())});
  } else if (b.mass_method == body::MassMethod::WindingCells) {
    out.push_back(
        {Verdict::Caveats,
         "the mesh is not a closed solid: its holes are not covered by particles (grains can get in), "
         "mass properties come from the winding-number solid"});
  } else {
    out.push_back({Verdict::Ok, "mass properties from the closed mesh"});
  }
}

// The certificate's bound when there is one, else the probes' figure (a lower bound only).
void judge_coverage(const body::ParticleBody::Quality& q, const VerdictThresholds& t, Findings& out) {
  if (q.certificate && q.certificate->certified) {
    out.push_back({Verdict::Ok, fmt::format("coverage certified (covering radius <= {:.3f} r)",
                                            q.certificate->bound_over_r)});
    return;
  }
  const double c = q.certificate ? q.certificate->bound_over_r : q.covering_over_r;
  const std::string what =
      q.certificate ? fmt::format("coverage NOT certified: covering radius <= {:.3f} r", c)
                    : fmt::format("no coverage certificate: probes found covering radius {:.3f} r", c);
  if (!std::isfinite(c) || c > t.unusable_bound_over_r) {
    out.push_back(
        {Verdict::NotUsable,
         fmt::format("{}, above {} r: grains smaller than {:.2f} r reach the mesh between the particles "
                     "(more --rounds or a smaller --radius)",
                     what, t.unusable_bound_over_r, c - 1.0)});
  } else {
    const std::string leak =
        c > 1.0
            ? fmt::format("grains smaller than {:.2f} r may reach the mesh between the particles", c - 1.0)
            : std::string("that the spheres cover the surface is not proven");
    out.push_back({Verdict::Caveats, what + ": " + leak});
  }
}

void judge_relaxation(const body::ParticleBody::Quality& q, const VerdictThresholds& t, Findings& out) {
  if (!q.converged) {
    out.push_back(
        {Verdict::Caveats,
         fmt::format("relaxation NOT converged after {} iterations (--max-iterations): the spacing may be "
                     "uneven",
                     q.iterations)});
  }
  const bool even = q.relative_radius >= t.min_relative_radius && q.cv <= t.max_cv;
  const std::string figures = fmt::format("rho {:.3f}, CV {:.3f}", q.relative_radius, q.cv);
  if (even) {
    out.push_back({Verdict::Ok, (q.converged ? "relaxation converged, " : "") + figures});
  } else {
    out.push_back({Verdict::Caveats, fmt::format("uneven spacing: {} (wanted rho >= {}, CV <= {})", figures,
                                                 t.min_relative_radius, t.max_cv)});
  }
}

void judge_thin_features(const ThinFeatures& thin, double radius, const VerdictThresholds& t, Findings& out) {
  if (thin.triangles == 0) {
    out.push_back({Verdict::Ok, "no thin features"});
    return;
  }
  const std::string share =
      fmt::format("thin features on {:.2f} % of the area in {} region{}", 100.0 * thin.area_share,
                  thin.regions.size(), thin.regions.size() == 1 ? "" : "s");
  const ThinRegion& largest = thin.regions.front();
  const std::string remedy = fmt::format("the largest ({:.2f} % of the area): {} (now {:.3g})",
                                         100.0 * largest.area_share, resolving_radii_text(largest), radius);
  if (thin.area_share <= t.max_thin_share) {
    out.push_back({Verdict::Ok, fmt::format("{} only: {}", share, remedy)});
  } else {
    out.push_back(
        {Verdict::Caveats, fmt::format("{}: particles of both sides overlap there; {}", share, remedy)});
  }
}

void judge_surface_distance(double phi_over_r, const VerdictThresholds& t, Findings& out) {
  const std::string text = fmt::format("largest |phi| {:.2e} r", phi_over_r);
  if (!std::isfinite(phi_over_r) || phi_over_r > t.unusable_phi_over_r) {
    out.push_back({Verdict::NotUsable, text + fmt::format(", above {} r: the particles are off the mesh",
                                                          t.unusable_phi_over_r)});
  } else if (phi_over_r > t.max_phi_over_r) {
    out.push_back({Verdict::Caveats,
                   text + fmt::format(", above {} r: some particles are off the mesh", t.max_phi_over_r)});
  } else {
    out.push_back({Verdict::Ok, text});
  }
}

}  // namespace

const char* verdict_name(Verdict verdict) {
  switch (verdict) {
    case Verdict::Ok:
      return "body OK";
    case Verdict::Caveats:
      return "usable with caveats";
    case Verdict::NotUsable:
      return "not usable";
  }
  return "not usable";
}

BodyVerdict judge_body(const body::ParticleBody& body, const ThinFeatures& thin,
                       const VerdictThresholds& thresholds) {
  const auto& q = body.quality;
  Findings findings;
  if (body.positions.size() <= body.interior_count)
    findings.push_back({Verdict::NotUsable, "no surface particles"});
  judge_coverage(q, thresholds, findings);
  judge_relaxation(q, thresholds, findings);
  judge_thin_features(thin, body.particle_radius, thresholds, findings);
  judge_surface_distance(q.max_abs_phi_over_r, thresholds, findings);
  judge_mass_properties(body, findings);
  std::stable_sort(findings.begin(), findings.end(),
                   [](const Finding& a, const Finding& b) { return a.verdict > b.verdict; });
  BodyVerdict out;
  out.verdict = findings.front().verdict;
  for (const Finding& f : findings)
    if (out.verdict == Verdict::Ok || f.verdict != Verdict::Ok) out.reasons.push_back(f.text);
  return out;
}

}  // namespace ts::sampler
