#pragma once
// Thin features: parts of the solid thinner than the particle spacing, where the particles of its two
// sides overlap and the body is bumpier than elsewhere. Found per triangle, then grouped into the
// connected regions a user can look at (an ear, a fin), each with its bounding box, its share of the
// surface and the particle radius that would resolve it. docs/body-format.md ("Verdict") says how
// `tetrasand sample` judges them.
#include <cstddef>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "sdf/exact_sdf.h"

namespace ts::sampler {

// The detector flags a triangle when, half a spacing s inward from its centroid, the point is less
// than s / 4 deep (or outside again). For a slab or a rod of thickness t that is exactly t < 0.75 s,
// so a spacing below t / 0.75 resolves it.
inline constexpr double kThinOverSpacing = 0.75;
// A suggested radius is this much below the one at which the detector would just pass the thinnest
// triangle, so that the search's rounding and a printed value's cannot leave it flagged.
inline constexpr double kResolvingMargin = 0.98;
// A region's tip often tapers to nothing (a claw, a fin's edge), so a radius that resolves all of it
// can be far smaller than one that resolves most of it: both are reported, "most" being this share
// of its area.
inline constexpr double kMostlyResolved = 0.9;

// One connected region of thin triangles (sharing a vertex counts as connected).
struct ThinRegion {
  Aabb box;  // m, of its triangles' vertices
  std::size_t triangles = 0;
  double area = 0.0;        // m^2
  double area_share = 0.0;  // of the whole mesh's surface area, 0..1
  // m, its smallest local thickness: kThinOverSpacing x the largest spacing at which the detector
  // passes a triangle (exactly the thickness of a slab or a rod, rims included); 0 for a knife edge
  double thinnest = 0.0;
  double resolving_radius = 0.0;         // m, a particle radius whose spacing flags none of it (0: none does)
  double mostly_resolving_radius = 0.0;  // m, one whose spacing passes kMostlyResolved of its area or more
};

struct ThinFeatures {
  double threshold = 0.0;           // m, kThinOverSpacing x the spacing: thinner than this is thin
  std::size_t triangles = 0;        // triangles whose solid is thinner than `threshold`
  Aabb where;                       // their centroids' bounding box
  double area_share = 0.0;          // their share of the surface area, 0..1
  std::vector<ThinRegion> regions;  // every region, largest area first
};

// Thin triangles of `mesh` at particle spacing `spacing` [m] for particles of radius `radius` [m]
// (the radius only scales the resolving radii: spacing / radius is the sampler's fixed ratio).
// TBB-parallel over triangles; the same mesh and spacing give the same result.
ThinFeatures find_thin_features(const TriangleMesh& mesh, const sdf::ExactDistance& exact, double spacing,
                                double radius);

// What the report and the verdict suggest for a region: "--radius A resolves 90 % of it, --radius B all
// of it", or that no radius does where its thinnest triangle passes at no spacing (a knife edge).
std::string resolving_radii_text(const ThinRegion& region);

// The report's last word on thin features: a smaller radius on the thin regions alone (a radius map) is
// not offered, since a body has one particle radius, and a smaller --radius or a larger --count
// resolves them everywhere. docs/body-format.md ("Thin features") has the measurement behind it.
std::string local_radius_advice();

}  // namespace ts::sampler
