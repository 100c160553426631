#include "sampler/sample_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <span>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/log.h"
#include "core/mass_properties.h"
#include "sampler/interior_fill.h"
#include "sampler/point_grid.h"
#include "sampler/sampling_quality.h"
#include "sampler/surface_points.h"
#include "sampler/winding_solid.h"
#include "sdf/exact_sdf.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"
#include "sdf/settings.h"

namespace ts::sampler {
namespace {

constexpr std::size_t kDefaultCount = 4000;
constexpr double kBandVoxels = 4.0;  // SDF half-width: 2 r at the default voxel, room for every move

// The radius and spacing the coverage target asks for. A hexagonal arrangement of spacing s has
// covering radius s / sqrt(3); a relaxed arrangement is not quite hexagonal and its covering radius
// comes out about kRelaxedCovering times larger (measured on the sphere and the bunny: 1.05-1.12),
// so covering radius c_t = coverage * r needs s = sqrt(3) c_t / kRelaxedCovering. The hole-closing
// rounds then mend what is left.
constexpr double kRelaxedCovering = 1.25;
struct Sizing {
  double radius = 0.0, spacing = 0.0;
  std::size_t count = 0;
};

Sizing size_particles(double area, const SampleSettings& s) {
  Sizing out;
  if (s.radius > 0.0) {
    out.radius = s.radius;
  } else {
    const std::size_t n = s.count > 0 ? s.count : kDefaultCount;
    // Invert count_for_coverage: N = 2A / (sqrt(3) s^2) with s = sqrt(3) coverage r.
    const double spacing = std::sqrt(2.0 * area / (std::sqrt(3.0) * static_cast<double>(n)));
    out.radius = spacing * kRelaxedCovering / (std::sqrt(3.0) * s.coverage);
  }
  out.spacing = std::sqrt(3.0) * s.coverage * out.radius / kRelaxedCovering;
  out.count = static_cast<std::size_t>(
      std::ceil(particles_for_covering_radius(area, s.coverage * out.radius / kRelaxedCovering)));
  return out;
}

void check_sizes(const Sizing& z, const SampleSettings& s, double area) {
  if (!(s.coverage > 0.0)) throw InputError(fmt::format("--coverage must be positive (got {})", s.coverage));
  if (z.count < 8) {
    throw InputError(fmt::format("particle radius {:.4g} m is too large for this mesh (area {:.4g} m^2): it would "
                                 "hold only {} particles; use a radius below {:.4g} m",
                                 z.radius, area, z.count, z.radius * std::sqrt(static_cast<double>(z.count) / 8.0)));
  }
  if (z.count > s.max_particles) {
    const double smallest = z.radius * std::sqrt(static_cast<double>(z.count) / static_cast<double>(s.max_particles));
    throw InputError(fmt::format("particle radius {:.4g} m needs about {} particles, above the cap of {}; the "
                                 "largest body that fits has {} particles (--count {}), the smallest radius that "
                                 "fits is {:.4g} m",
                                 z.radius, z.count, s.max_particles, s.max_particles, s.max_particles, smallest));
  }
}

// With --fill the interior lattice grows as r^-3 against the surface's r^-2: the cap names the
// smallest radius whose filled body fits (found by bisection on the scale of r). The interior is
// counted as the whole volume's lattice points, an upper bound.
void check_filled_size(const Sizing& z, const MassProperties& mass, std::size_t cap) {
  const double interior = mass.volume * interior_lattice_density(z.radius);
  const auto total = [&](double scale) { return static_cast<double>(z.count) / (scale * scale) + interior / (scale * scale * scale); };
  if (total(1.0) <= static_cast<double>(cap)) return;
  double lo = 1.0, hi = 2.0;
  while (total(hi) > static_cast<double>(cap)) hi *= 2.0;
  for (int i = 0; i < 60; ++i) (total(0.5 * (lo + hi)) > static_cast<double>(cap) ? lo : hi) = 0.5 * (lo + hi);
  throw InputError(fmt::format("--fill at radius {:.4g} m adds about {:.0f} interior particles to {} on the surface, "
                               "above the cap of {}; the smallest radius whose filled body fits is {:.4g} m",
                               z.radius, interior, z.count, cap, z.radius * hi));
}

// The SDF grid: voxel r / 2 unless the user set one; grown while the dense texture would exceed the
// budget (then the trilinear error grows too, so say so).
sdf::GridSpec choose_grid(const TriangleMesh& mesh, double radius, const SampleSettings& s,
                          std::vector<std::string>& warnings) {
  sdf::SdfSettings grid;
  grid.voxel_size = s.voxel_size > 0.0 ? s.voxel_size : 0.5 * radius;
  grid.band = kBandVoxels;
  // The texture budget below decides; make_grid's own cap (far larger) must not refuse first.
  grid.max_voxels = std::numeric_limits<std::size_t>::max();
  for (;;) {
    const sdf::GridSpec spec = sdf::make_grid(bounding_box(mesh), grid);
    if (static_cast<double>(spec.voxel_count()) * 16.0 <= static_cast<double>(s.max_sdf_bytes)) {
      if (grid.voxel_size > 0.5 * radius && s.voxel_size <= 0.0) {
        warnings.push_back(fmt::format("the SDF voxel was enlarged to {:.4g} m (r / {:.2f}) to fit the {} MiB texture "
                                       "budget; relaxation is coarser, the exact projection keeps particles on the surface",
                                       grid.voxel_size, radius / grid.voxel_size, s.max_sdf_bytes >> 20));
      }
      return spec;
    }
    if (s.voxel_size > 0.0) {
      throw InputError(fmt::format("SDF voxel {:.4g} m needs {} MiB of GPU texture, above the budget of {} MiB",
                                   s.voxel_size, spec.voxel_count() * 16 >> 20, s.max_sdf_bytes >> 20));
    }
    grid.voxel_size *= 1.25;
  }
}

// After an injection, the particles within `radius` of a new one move, the others are frozen; the new
// ones (appended after `particles`) move too.
constexpr double kMobileRadiusOverSpacing = 2.5;
constexpr int kLocalIterations = 200;
constexpr int kNeighbourRounds = 3;
constexpr std::size_t kScoutProbeFraction = 4;
std::vector<std::uint8_t> mobile_near_injections(const std::vector<Eigen::Vector3d>& particles,
                                                 const std::vector<UncoveredPoint>& holes, double radius) {
  std::vector<Eigen::Vector3d> injected;
  for (const auto& h : holes) injected.push_back(h.position);
  const PointGrid grid(injected, std::max(radius, 1e-300));
  std::vector<std::uint8_t> mobile(particles.size() + holes.size(), 1);
  tbb::parallel_for(std::size_t{0}, particles.size(), [&](std::size_t i) {
    mobile[i] = radius > 0.0 && grid.nearest(particles[i]).distance <= radius ? 1 : 0;
  });
  return mobile;
}

// Redundant particles: where a feature is thinner than a voxel (an ear tip, a blade) the smoothed
// field has no zero level set and relaxed particles collect in its sink, and the exact projection can
// put two onto one vertex. Of each pair closer than `min_distance` [m] the later one is dropped
// (greedy, in index order: deterministic); the coverage measurement that follows re-injects a particle
// wherever that opened a hole, at least r from every other one.
constexpr double kCrowdedOverSpacing = 0.6;
std::size_t drop_crowded(std::vector<Eigen::Vector3d>& particles, std::vector<Eigen::Vector3d>& normals,
                         double min_distance) {
  if (particles.size() < 2) return 0;
  const PointGrid grid(particles, min_distance);
  std::vector<std::uint8_t> crowded(particles.size(), 0);
  tbb::parallel_for(std::size_t{0}, particles.size(), [&](std::size_t i) {
    crowded[i] = grid.nearest(particles[i], i).distance < min_distance ? 1 : 0;
  });
  // Only crowded particles can be dropped; a crowded one survives when no kept particle is too close.
  std::vector<std::size_t> kept_crowded;
  std::size_t out = 0;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (crowded[i]) {
      bool clash = false;
      for (const std::size_t k : kept_crowded) clash = clash || (particles[k] - particles[i]).norm() < min_distance;
      if (clash) continue;
      kept_crowded.push_back(out);
    }
    particles[out] = particles[i];
    normals[out] = normals[i];
    ++out;
  }
  const std::size_t dropped = particles.size() - out;
  particles.resize(out);
  normals.resize(out);
  return dropped;
}

std::vector<Eigen::Vector3f> to_local(const std::vector<Eigen::Vector3d>& world, const Eigen::Vector3d& origin) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(world.size());
  for (const auto& p : world) out.push_back((p - origin).cast<float>());
  return out;
}

// Moves each particle to its exact closest point on the mesh and returns the outward normal there
// (the pseudonormal of the feature holding it).
void project_exactly(const sdf::ExactDistance& exact, std::vector<Eigen::Vector3d>& points,
                     std::vector<Eigen::Vector3d>& normals) {
  normals.resize(points.size());
  tbb::parallel_for(std::size_t{0}, points.size(), [&](std::size_t i) {
    const sdf::ClosestPoint c = exact.closest(points[i]);
    points[i] = c.point;
    normals[i] = exact.feature_normal(c);
  });
}

// On an open or inconsistently oriented mesh a pseudonormal can point inwards. The outward side is
// where the winding number drops: a normal whose tip (a quarter radius out) sees a clearly larger
// |w| than its tail is turned round. Thin features (both ends outside, |w| about 0) keep theirs.
void orient_normals_by_winding(const sdf::ExactDistance& exact, const std::vector<Eigen::Vector3d>& points,
                               std::vector<Eigen::Vector3d>& normals, double radius) {
  tbb::parallel_for(std::size_t{0}, points.size(), [&](std::size_t i) {
    const Eigen::Vector3d step = 0.25 * radius * normals[i];
    const double ahead = std::abs(exact.winding_number(points[i] + step));
    const double behind = std::abs(exact.winding_number(points[i] - step));
    if (ahead - behind > 0.5) normals[i] = -normals[i];
  });
}

ThinFeatures find_thin_features(const TriangleMesh& mesh, const sdf::ExactDistance& exact, double spacing) {
  const sdf::Pseudonormals& pn = exact.pseudonormals();
  // A triangle whose solid is thinner than the spacing: half a spacing inward from its centroid,
  // the point is already outside again or barely inside.
  ThinFeatures thin;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d centroid = (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3.0;
    const Eigen::Vector3d probe = centroid - 0.5 * spacing * pn.face[t];
    if (exact.signed_distance(probe, sdf::SignMethod::Pseudonormal) > -0.25 * spacing) {
      ++thin.triangles;
      thin.where.extend(centroid);
    }
  }
  return thin;
}

}  // namespace

SampleResult sample_mesh(gpu::Context& context, const TriangleMesh& mesh, const SampleSettings& settings,
                         const std::function<void(const SampleProgress&)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  SampleResult result;
  const double area = surface_area(mesh);
  if (!(area > 0.0)) throw InputError("the mesh has no surface area");
  // A closed mesh's mass properties come first, so a zero-volume mesh is refused before any GPU work;
  // the winding-number solid's need the exact distance below.
  std::optional<MassProperties> mass;
  if (settings.mass_method == body::MassMethod::ClosedMesh) mass = compute_mass_properties(mesh, settings.density);
  const Sizing z = size_particles(area, settings);
  check_sizes(z, settings, area);
  if (settings.fill && mass) check_filled_size(z, *mass, settings.max_particles);
  result.estimated_count = z.count;

  // 1. SDF, kept on the GPU as a dense texture.
  const sdf::GridSpec spec = choose_grid(mesh, z.radius, settings, result.warnings);
  const sdf::Pseudonormals normals = sdf::compute_pseudonormals(mesh);
  sdf::ScanConvertOptions scan;
  scan.band = kBandVoxels;
  scan.keep_texture = true;
  scan.build_grid = false;
  scan.timings = settings.timings;
  sdf::ScanConvertResult field = sdf::scan_convert(context, mesh, normals, spec, scan);
  const sdf::ExactDistance exact(mesh);
  double mass_cell = 0.0;
  if (!mass) {
    const WindingSolid solid = winding_mass_properties(mesh, exact, settings.density, settings.mass_cell);
    mass = solid.mass;
    mass_cell = solid.cell;
  }
  if (settings.fill && settings.mass_method == body::MassMethod::WindingCells) check_filled_size(z, *mass, settings.max_particles);
  if (settings.fill) {
    result.estimated_interior = std::max(mass->volume - area * z.radius, 0.0) * interior_lattice_density(z.radius);
  }

  // 2. Seeds.
  std::mt19937_64 rng(settings.seed);
  std::vector<Eigen::Vector3d> particles = sample_surface_points(mesh, z.count, rng).positions;

  // 3-4. Relax, project, measure coverage, inject, relax locally, repeat.
  GpuRelaxer relaxer(context, std::move(field.texture), settings.timings);
  RelaxSettings relax = settings.relax;
  relax.spacing = z.spacing;
  relax.band_limit = 0.95 * kBandVoxels * spec.voxel_size;
  const double target = settings.coverage * z.radius;
  int iterations = 0, rounds = 0;
  bool converged = true;
  std::vector<Eigen::Vector3d> particle_normals;
  std::vector<std::uint8_t> mobile(particles.size(), 1);
  CoverageResult coverage;
  bool relax_round = true;
  for (;;) {
    if (relax_round) {
    std::vector<Eigen::Vector3f> local = to_local(particles, spec.origin);
    const RelaxStats stats = relaxer.relax(local, relax, [&](int it, std::size_t n, double residual) {
      if (progress) progress({rounds, iterations + it, n, residual});
    }, &mobile);
    iterations += stats.iterations;
    // "Converged" is the global relaxation's verdict; the local ones after an injection stop at
    // kLocalIterations (their residual, logged, sits near 1.5 x the tolerance: the compressed rim).
    if (rounds == 0) converged = stats.converged;
    log::debug("sampler round {}: {} iterations, residual {:.3g}, {} of {} particles mobile", rounds, stats.iterations,
               stats.mean_move_over_spacing, std::count(mobile.begin(), mobile.end(), 1), mobile.size());
    particles.clear();
    for (const auto& p : local) particles.push_back(p.cast<double>() + spec.origin);
    }
    project_exactly(exact, particles, particle_normals);
    const std::size_t dropped = drop_crowded(particles, particle_normals, kCrowdedOverSpacing * z.spacing);
    if (dropped > 0) log::debug("sampler round {}: dropped {} crowded particles", rounds, dropped);
    // Holes are hunted with a quarter of the probes (a 1M-probe pass costs more than a local
    // relaxation on llvmpipe); the reported figure always comes from a full pass, and when that one
    // still finds holes its worst points feed the next injection.
    CoverageSettings probe;
    probe.seed = settings.seed + 1000u * static_cast<unsigned>(rounds + 1);
    probe.worst_k = std::max<std::size_t>(1, particles.size() / 10);
    probe.min_depth = target;  // only real holes
    probe.probes = std::max<std::size_t>(settings.probes / kScoutProbeFraction, 1);
    coverage = measure_coverage(mesh, std::span<const Eigen::Vector3d>(particles), probe);
    if (coverage.covering_radius <= target || rounds >= settings.max_rounds) {
      probe.probes = settings.probes;
      probe.seed += 500u;
      coverage = measure_coverage(mesh, std::span<const Eigen::Vector3d>(particles), probe);
    }
    log::debug("sampler round {}: covering radius {:.4f} r over {} probes, {} holes deeper than the target", rounds,
               coverage.covering_radius / z.radius, probe.probes, coverage.worst.size());
    if (coverage.covering_radius <= target || rounds >= settings.max_rounds) break;
    // Inject at the worst uncovered surface points (already on the surface); only they and the
    // particles near them relax again, so the rest of the arrangement (and its holes, already
    // measured) stays as it is.
    // The first rounds relax the new particles with their neighbours (better spacing). Later ones
    // only place them: a particle at the deepest point of a hole, on the surface and at least r from
    // every other one, can only shrink holes, never open one elsewhere, so the rounds converge.
    relax_round = rounds < kNeighbourRounds;
    mobile = mobile_near_injections(particles, coverage.worst, kMobileRadiusOverSpacing * z.spacing);
    for (const auto& hole : coverage.worst) particles.push_back(hole.position);
    relax.max_iterations = std::min(relax.max_iterations, kLocalIterations);
    ++rounds;
  }
  if (coverage.covering_radius > target) {
    result.warnings.push_back(fmt::format("coverage target not reached after {} rounds: covering radius {:.4g} m = {:.3f} r "
                                          "(target {:.3f} r)",
                                          rounds, coverage.covering_radius, coverage.covering_radius / z.radius,
                                          settings.coverage));
  }

  // 5. Quality and the body.
  const SpacingStatistics spacing = spacing_statistics(area, std::span<const Eigen::Vector3d>(particles));
  const double max_phi = max_distance_to_surface(mesh, std::span<const Eigen::Vector3d>(particles));
  result.thin = find_thin_features(mesh, exact, z.spacing);
  if (result.thin.triangles > 0) {
    result.warnings.push_back(fmt::format("{} triangles belong to features thinner than the particle spacing {:.4g} m "
                                          "(within [{:.4g}, {:.4g}, {:.4g}] .. [{:.4g}, {:.4g}, {:.4g}] m): particles of "
                                          "both sides overlap there",
                                          result.thin.triangles, z.spacing, result.thin.where.min.x(),
                                          result.thin.where.min.y(), result.thin.where.min.z(), result.thin.where.max.x(),
                                          result.thin.where.max.y(), result.thin.where.max.z()));
  }
  if (settings.sign == sdf::SignMethod::Winding) orient_normals_by_winding(exact, particles, particle_normals, z.radius);
  body::ParticleBody& body = result.body;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    body.positions.push_back(particles[i].cast<float>());
    body.normals.push_back(particle_normals[i].cast<float>());
  }
  if (settings.fill) {
    // Surface quality figures above are of the surface layer alone.
    const std::vector<Eigen::Vector3d> interior = fill_interior(exact, bounding_box(mesh), mass->center_of_mass, z.radius,
                                                               settings.sign);
    for (const auto& p : interior) {
      body.positions.push_back(p.cast<float>());
      body.normals.push_back(Eigen::Vector3f::Zero());
    }
    body.interior_count = interior.size();
  }
  body.particle_radius = z.radius;
  set_mass_properties(body, *mass);
  if (settings.mass_method == body::MassMethod::WindingCells) {
    body.mass_method = body::MassMethod::WindingCells;
    body.mass_cell = mass_cell;
  }
  body.sdf_voxel_size = spec.voxel_size;
  body.quality.relative_radius = spacing.relative_radius;
  body.quality.cv = spacing.cv_nn;
  body.quality.covering_radius = coverage.covering_radius;
  body.quality.covering_over_r = coverage.covering_radius / z.radius;
  if (settings.grain_radius > 0.0) {
    body.quality.covering_over_r_plus_grain = coverage.covering_radius / (z.radius + settings.grain_radius);
  }
  body.quality.max_abs_phi_over_r = max_phi / z.radius;
  body.quality.iterations = iterations;
  body.quality.injection_rounds = rounds;
  body.quality.converged = converged;
  body.quality.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (settings.timings) result.timing_report = field.stats.timing_report + relaxer.timing_report();
  return result;
}

}  // namespace ts::sampler
