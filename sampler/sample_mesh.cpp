#include "sampler/sample_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <variant>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/log.h"
#include "core/mass_properties.h"
#include "core/mesh_report.h"
#include "core/stopwatch.h"
#include "gpu/host_sync.h"
#include "sampler/cpu_coverage_certificate.h"
#include "sampler/cpu_relaxer.h"
#include "sampler/gpu_relaxer.h"
#include "sampler/interior_fill.h"
#include "sampler/point_grid.h"
#include "sampler/sampling_quality.h"
#include "sampler/surface_points.h"
#include "sampler/winding_solid.h"
#include "sdf/exact_sdf.h"
#include "sdf/grid.h"
#include "sdf/host_field.h"
#include "sdf/leaf_field.h"
#include "sdf/openvdb_compare.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"
#include "sdf/settings.h"

namespace ts::sampler {
namespace {

// Neither --radius nor --count: bench/defaults_criteria.md's rule over 1000-16000 particles on five meshes
// (docs/benchmarks.md, "Defaults"): every verdict is as good as it gets from 8000 on (CGAL's dino: OK).
constexpr std::size_t kDefaultCount = 8000;
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

// The particles are floats, on the GPU and in the PLY, and the relaxation compares squared steps down
// to 1e-4 of the radius: (1e-4 r)^2 must stay a normal float, so r >= sqrt(FLT_MIN) / 1e-4, about
// 1.1e-15 m. A body that small is a mesh in the wrong units, not a particle body.
const double kSmallestRadius = std::sqrt(static_cast<double>(std::numeric_limits<float>::min())) / 1e-4;

void check_sizes(const Sizing& z, const SampleSettings& s, double area) {
  if (!(s.coverage > 0.0)) throw InputError(fmt::format("--coverage must be positive (got {})", s.coverage));
  if (!(z.radius >= kSmallestRadius)) {
    throw InputError(
        fmt::format("particle radius {:.3g} m is below {:.2g} m, the smallest the sampler's float "
                    "arithmetic resolves (the mesh is {:.3g} m^2 in area): is the mesh in the wrong "
                    "units? --scale multiplies its coordinates",
                    z.radius, kSmallestRadius, area));
  }
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

// The SDF grid: voxel r / 2 unless the user set one, so trilinear interpolation error stays far below
// r. The grid is sparse on the GPU (only its band is stored), so the box's size sets no limit.
sdf::GridSpec choose_grid(const TriangleMesh& mesh, double radius, const SampleSettings& s) {
  sdf::SdfSettings grid;
  grid.voxel_size = s.voxel_size > 0.0 ? s.voxel_size : 0.5 * radius;
  grid.band = kBandVoxels;
  grid.max_voxels = std::numeric_limits<std::size_t>::max();  // the box is never allocated
  return sdf::make_grid(bounding_box(mesh), grid);
}

// After an injection, the particles within `radius` of a new one move, the others are frozen; the new
// ones (appended after `particles`) move too.
constexpr double kMobileRadiusOverSpacing = 2.5;
constexpr int kLocalIterations = 200;
constexpr int kNeighbourRounds = 3;
std::vector<std::uint8_t> mobile_near_injections(const std::vector<Eigen::Vector3d>& particles,
                                                 const std::vector<UncoveredPiece>& holes, double radius) {
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

// What is decided before any GPU work: the particle size, and the mass properties of the solid.
struct SamplingPlan {
  double area = 0.0;  // m^2
  Sizing z;
  MassProperties mass;
  double mass_cell = 0.0;  // m, finest octree cell of body::MassMethod::WindingCells (else 0)
};

// Validates the mesh and sizes the body. A closed mesh's mass properties come first, so a
// zero-volume mesh is refused before anything else; every size check happens here, before the SDF.
SamplingPlan plan_sampling(const TriangleMesh& mesh, const sdf::ExactDistance& exact, const SampleSettings& settings,
                           SampleResult& result) {
  SamplingPlan plan;
  plan.area = surface_area(mesh);
  const bool closed = settings.mass_method == body::MassMethod::ClosedMesh;
  if (closed) plan.mass = compute_mass_properties(mesh, settings.density);
  plan.z = size_particles(plan.area, settings);
  check_sizes(plan.z, settings, plan.area);
  if (!closed) {
    const WindingSolid solid = winding_mass_properties(mesh, exact, settings.density, settings.mass_cell);
    plan.mass = solid.mass;
    plan.mass_cell = solid.cell;
  }
  if (settings.fill) check_filled_size(plan.z, plan.mass, settings.max_particles);
  result.estimated_count = plan.z.count;
  if (settings.fill) {
    result.estimated_interior =
        std::max(plan.mass.volume - plan.area * plan.z.radius, 0.0) * interior_lattice_density(plan.z.radius);
  }
  return plan;
}

// A sparse field above --sdf-budget-mib: its bytes grow as the band's area, ~ 1 / voxel^2, so the
// voxel that fits is h sqrt(bytes / budget), and with the voxel following the radius the particle
// count that fits is N budget / bytes.
// `size`: the field's size in words ("N band voxels").
[[noreturn]] void throw_over_budget(const sdf::GridSpec& spec, std::size_t bytes, const std::string& size,
                                    const SamplingPlan& plan, const SampleSettings& settings,
                                    const char* where) {
  const double over = static_cast<double>(bytes) / static_cast<double>(settings.max_sdf_bytes);
  const std::string remedy =
      settings.voxel_size > 0.0
          ? fmt::format("a --voxel of at least {:.4g} m fits it", spec.voxel_size * std::sqrt(over))
          : fmt::format("about {:.0f} particles fit it", static_cast<double>(plan.z.count) / over);
  throw InputError(fmt::format(
      "the sparse SDF at voxel {:.4g} m ({}) needs {:.1f} MiB of {} memory, above "
      "the budget of {} MiB (--sdf-budget-mib); {}, or raise the budget",
      spec.voxel_size, size, bytes / 1048576.0, where, settings.max_sdf_bytes >> 20, remedy));
}

bool relax_on_cpu(const gpu::Context* context, const SampleSettings& settings) {
  return gpu::resolve_backend(settings.backend, context) == gpu::Backend::Cpu;
}

gpu::Context& needed_context(gpu::Context* context, const char* stage) {
  if (context == nullptr)
    throw Error(ExitCode::Internal, fmt::format("sample_mesh: {} needs a GL context", stage));
  return *context;
}

// The level set of the band in index space: by GPU scan conversion, or by exact distance on the CPU
// (both signed by pseudonormals, as the relaxation expects), or by OpenVDB on the CPU (its own signs).
openvdb::FloatGrid::Ptr band_level_set(gpu::Context* context, const TriangleMesh& mesh,
                                       const sdf::ExactDistance& exact, const sdf::GridSpec& spec,
                                       const SampleSettings& settings, SampleResult& result) {
  FieldStats& f = result.field;
  if (result.sdf_path == SdfPath::OpenVdb) {
    openvdb::FloatGrid::Ptr grid = sdf::openvdb_index_level_set(mesh, spec, kBandVoxels);
    f.band_voxels = grid->activeVoxelCount();
    return grid;
  }
  if (result.sdf_path == SdfPath::Exact) {
    openvdb::FloatGrid::Ptr grid =
        sdf::exact_sdf_grid(exact, mesh, spec, kBandVoxels, sdf::SignMethod::Pseudonormal, true);
    f.band_voxels = grid->activeVoxelCount();
    return grid;
  }
  const sdf::Pseudonormals normals = sdf::compute_pseudonormals(mesh);
  sdf::ScanConvertOptions scan;
  scan.method = settings.scan;
  scan.band = kBandVoxels;
  scan.index_space_grid = true;
  scan.timings = settings.timings;
  const sdf::ScanConvertResult converted =
      sdf::scan_convert(needed_context(context, "the GPU scan conversion"), mesh, normals, spec, scan);
  f.band_voxels = converted.stats.band_voxels;
  f.scan = converted.stats.method;
  f.readback_bytes = converted.stats.readback_bytes;
  f.scan_peak_gpu_bytes = converted.stats.peak_gpu_bytes;
  result.timing_report = converted.stats.timing_report;
  return converted.grid;
}

// The finest grid whose GPU field fits `limit` bytes, coarsening `spec`'s voxel from the square law
// (the band's leaves grow as 1 / voxel^2) in steps of 2 %; an empty spec when none does.
sdf::GridSpec largest_fitting_grid(const TriangleMesh& mesh, const SamplingPlan& plan, const SampleSettings& settings,
                                   const sdf::GridSpec& spec, std::size_t bytes, std::size_t limit) {
  SampleSettings coarser = settings;
  coarser.voxel_size = spec.voxel_size * std::max(1.0, 0.9 * std::sqrt(static_cast<double>(bytes) / limit));
  for (int step = 0; step < 500; ++step, coarser.voxel_size *= 1.02) {
    const sdf::GridSpec fitting = choose_grid(mesh, plan.z.radius, coarser);
    if (sdf::leaf_field_bytes(fitting, sdf::band_leaf_bound(mesh, fitting, kBandVoxels)) <= limit) return fitting;
  }
  return {};
}

// A GPU field of `bytes` above the GPU memory `limit`: exit 3 before any GPU work, naming the finest
// grid that fits.
[[noreturn]] void throw_over_gpu_memory(const TriangleMesh& mesh, const SamplingPlan& plan,
                                        const SampleSettings& settings, const sdf::GridSpec& spec, std::size_t bytes,
                                        std::size_t limit) {
  const sdf::GridSpec fits = largest_fitting_grid(mesh, plan, settings, spec, bytes, limit);
  const std::string what =
      fits.voxel_size > 0.0
          ? fmt::format("the largest resolution that fits is a voxel of {:.4g} m ({} x {} x {} voxels): --voxel {:.4g}",
                        fits.voxel_size, fits.dims.x(), fits.dims.y(), fits.dims.z(), fits.voxel_size)
          : std::string("no resolution fits");
  throw GpuError(fmt::format("the SDF on the GPU at voxel {:.4g} m ({} x {} x {} voxels) needs up to {:.1f} MiB, above "
                             "the {:.1f} MiB of GPU memory it may take{}; {}",
                             spec.voxel_size, spec.dims.x(), spec.dims.y(), spec.dims.z(), bytes / 1048576.0,
                             limit / 1048576.0,
                             std::getenv("TETRASAND_GPU_MEMORY_MIB") ? " (TETRASAND_GPU_MEMORY_MIB)" : "", what));
}

// The GPU path's field (sdf::LeafField): scan-converted on the GPU and kept there, no host round trip
// and no byte of it read back. Sized before any GPU work from the band's leaf bound: above the budget
// or the GPU's memory it stops; past one storage block (the leaf field's limit; llvmpipe's 128 MiB) it
// gives way to the host path (std::nullopt), whose NanoVDB field is cut into chunks.
std::optional<sdf::LeafField> resident_field(gpu::Context& context, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                                             const SamplingPlan& plan, const SampleSettings& settings,
                                             SampleResult& result) {
  const std::size_t slots = sdf::band_leaf_bound(mesh, spec, kBandVoxels);
  const std::size_t bytes = sdf::leaf_field_bytes(spec, slots);
  if (bytes > settings.max_sdf_bytes) {
    throw_over_budget(spec, bytes, fmt::format("up to {} leaves of 8^3 voxels", slots), plan, settings, "GPU");
  }
  if (const std::size_t limit = sdf::gpu_field_memory_limit(); limit > 0 && bytes > limit) {
    throw_over_gpu_memory(mesh, plan, settings, spec, bytes, limit);
  }
  if (static_cast<double>(slots * sdf::kLeafBytes) > static_cast<double>(context.limits().max_ssbo_bytes)) {
    log::info("the GPU field ({} leaves) passes one storage block: the field goes through the host", slots);
    return std::nullopt;
  }
  sdf::ScanConvertOptions scan;
  scan.method = settings.scan;
  scan.band = kBandVoxels;
  scan.build_grid = false;
  scan.gpu_field = true;
  scan.gpu_field_slots = slots;
  scan.timings = settings.timings;
  sdf::ScanConvertResult converted = sdf::scan_convert(context, mesh, sdf::compute_pseudonormals(mesh), spec, scan);
  FieldStats& f = result.field;
  f.band_voxels = converted.stats.band_voxels;
  f.scan = converted.stats.method;
  f.readback_bytes = converted.stats.readback_bytes;
  f.scan_peak_gpu_bytes = converted.stats.peak_gpu_bytes;
  f.gpu_bytes = converted.field->gpu_bytes();
  f.host_bytes = 0;
  f.gpu_resident = true;
  result.timing_report = converted.stats.timing_report;
  return std::move(converted.field);
}

// The SDF for the relaxation. On the GPU path, the field built and kept on the GPU (resident_field).
// Else the band as an index-space level set (any voxel size), a sparse NanoVDB field, uploaded for the
// GPU relaxation or kept on the host for the CPU's. The field's size is checked against the budget
// first; it grows as the particle count (band voxels ~ area / voxel^2 ~ count).
using RelaxField = std::variant<sdf::SparseField, sdf::HostField, sdf::LeafField>;
RelaxField make_field(gpu::Context* context, const TriangleMesh& mesh, const sdf::ExactDistance& exact,
                      const sdf::GridSpec& spec, const SamplingPlan& plan, const SampleSettings& settings,
                      SampleResult& result) {
  result.sdf_path = choose_sdf_path(context, settings);
  if (result.sdf_path == SdfPath::Scan && !result.relax_on_cpu) {
    std::optional<sdf::LeafField> resident =
        resident_field(needed_context(context, "the GPU scan conversion"), mesh, spec, plan, settings, result);
    if (resident) return std::move(*resident);
  }
  const openvdb::FloatGrid::Ptr grid = band_level_set(context, mesh, exact, spec, settings, result);
  // CPU and GPU read the same grid, in the level set's own index space.
  sdf::NanoGrid nano = sdf::to_nanovdb(*grid);
  FieldStats& f = result.field;
  f.host_bytes = grid->memUsage() + nano.size();
  if (nano.size() > settings.max_sdf_bytes) {
    throw_over_budget(spec, nano.size(), fmt::format("{} band voxels", f.band_voxels), plan, settings,
                      result.relax_on_cpu ? "host" : "GPU");
  }
  if (result.relax_on_cpu) return sdf::HostField(std::move(nano), spec, kBandVoxels);
  needed_context(context, "the GPU relaxation");
  sdf::SparseField field(std::move(nano), spec, kBandVoxels);
  f.gpu_bytes = field.gpu_bytes();
  return field;
}

std::unique_ptr<ParticleRelaxer> make_relaxer(gpu::Context* context, RelaxField field, bool timings) {
  if (auto* host = std::get_if<sdf::HostField>(&field)) return std::make_unique<CpuRelaxer>(std::move(*host));
  if (auto* leaves = std::get_if<sdf::LeafField>(&field)) {
    return std::make_unique<GpuRelaxer>(*context, std::make_unique<const sdf::LeafField>(std::move(*leaves)), timings);
  }
  return std::make_unique<GpuRelaxer>(*context, std::move(std::get<sdf::SparseField>(field)), timings);
}

// The coverage certificate on the device the backend chose, behind one call: every certifier takes
// the particles as a body stores them and promises the same certificate (docs/coverage-certificate.md).
class Certifier {
 public:
  virtual ~Certifier() = default;
  virtual CoverageCertificate certify(std::span<const Eigen::Vector3f> centres, double radius,
                                      const CertificateSettings& settings) = 0;
  virtual std::string timing_report() = 0;
};

template <class Impl>
class CertifierOf final : public Certifier {
 public:
  template <class... Args>
  explicit CertifierOf(Args&&... args) : impl_(std::forward<Args>(args)...) {}
  CoverageCertificate certify(std::span<const Eigen::Vector3f> centres, double radius,
                              const CertificateSettings& settings) override {
    return impl_.certify(centres, radius, settings);
  }
  std::string timing_report() override {
    if constexpr (requires { impl_.timing_report(); }) return impl_.timing_report();
    return {};
  }

 private:
  Impl impl_;
};

// The certificate follows the relaxation's backend: on the CPU (sampler/cpu_coverage_certificate.h,
// double precision, TBB) wherever the relaxation runs there, for the same reasons.
std::unique_ptr<Certifier> make_certifier(gpu::Context* context, const TriangleMesh& mesh,
                                          const SampleSettings& settings, SampleResult& result) {
  result.certificate_on_cpu = result.relax_on_cpu;
  if (result.certificate_on_cpu) return std::make_unique<CertifierOf<CpuCoverageCertifier>>(mesh);
  return std::make_unique<CertifierOf<GpuCoverageCertifier>>(
      needed_context(context, "the GPU coverage certificate"), mesh, settings.timings);
}

// The particles as a body stores them (float, mesh coordinates): what the certificate and the probes judge.
std::vector<Eigen::Vector3f> as_stored(const std::vector<Eigen::Vector3d>& particles) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(particles.size());
  for (const auto& p : particles) out.push_back(p.cast<float>());
  return out;
}

// The particle arrangement as the hole-closing rounds leave it.
struct Arrangement {
  std::vector<Eigen::Vector3d> particles;  // m, on the surface
  std::vector<Eigen::Vector3d> normals;    // unit outward normals
  CoverageCertificate certificate;         // of the last round, at the target covering radius
  int certificates = 0;                    // computed, all rounds
  double certificate_seconds = 0.0;        // s, their wall time
  double relax_seconds = 0.0, projection_seconds = 0.0, injection_seconds = 0.0;  // s, all rounds
  int iterations = 0, rounds = 0;
  bool converged = true;                   // the global (first) relaxation's verdict
};

// Relax, project, certify coverage, inject at the deepest holes it proves, relax locally, repeat
// (sample_mesh.h step 4), until the certificate holds at the target radius or the round limit.
class HoleClosing {
 public:
  HoleClosing(ParticleRelaxer& relaxer, Certifier& certifier, const sdf::ExactDistance& exact,
              const sdf::GridSpec& spec, const SamplingPlan& plan, const SampleSettings& settings,
              const std::function<void(const SampleProgress&)>& progress)
      : relaxer_(relaxer),
        certifier_(certifier),
        exact_(exact),
        spec_(spec),
        plan_(plan),
        settings_(settings),
        progress_(progress),
        target_(settings.coverage * plan.z.radius) {
    relax_ = settings.relax;
    relax_.spacing = plan.z.spacing;
    relax_.band_limit = 0.95 * kBandVoxels * spec.voxel_size;
  }

  Arrangement run(std::vector<Eigen::Vector3d> seeds) {
    out_.particles = std::move(seeds);
    mobile_.assign(out_.particles.size(), 1);
    bool relax_round = true;
    for (;;) {
      if (relax_round) timed(out_.relax_seconds, [&] { relax(); });
      timed(out_.projection_seconds, [&] { project_and_thin(); });
      certify();
      if (out_.certificate.covered || out_.rounds >= settings_.max_rounds) break;
      // The first rounds relax the new particles with their neighbours (better spacing). Later ones
      // only place them: a particle at an uncovered point, on the surface and about r or more from
      // every other one, can only shrink holes, never open one elsewhere, so the rounds converge.
      relax_round = out_.rounds < kNeighbourRounds;
      bool injected = false;
      timed(out_.injection_seconds, [&] { injected = inject(); });
      if (!injected) break;
    }
    return std::move(out_);
  }

 private:
  void relax() {
    std::vector<Eigen::Vector3f> local = to_local(out_.particles, spec_.origin);
    const RelaxStats stats = relaxer_.relax(local, relax_, [&](int it, std::size_t n, double residual) {
      if (progress_) progress_({out_.rounds, out_.iterations + it, n, residual});
    }, &mobile_);
    out_.iterations += stats.iterations;
    // "Converged" is the global relaxation's verdict; the local ones after an injection stop at
    // kLocalIterations (their residual, logged, sits near 1.5 x the tolerance: the compressed rim).
    if (out_.rounds == 0) out_.converged = stats.converged;
    log::debug("sampler round {}: {} iterations, residual {:.3g}, {} of {} particles mobile", out_.rounds,
               stats.iterations, stats.mean_move_over_spacing, std::count(mobile_.begin(), mobile_.end(), 1),
               mobile_.size());
    out_.particles.clear();
    for (const auto& p : local) out_.particles.push_back(p.cast<double>() + spec_.origin);
  }

  void project_and_thin() {
    project_exactly(exact_, out_.particles, out_.normals);
    const std::size_t dropped = drop_crowded(out_.particles, out_.normals, kCrowdedOverSpacing * plan_.z.spacing);
    if (dropped > 0) log::debug("sampler round {}: dropped {} crowded particles", out_.rounds, dropped);
  }

  void certify() {
    const auto start = std::chrono::steady_clock::now();
    out_.certificate = certifier_.certify(as_stored(out_.particles), target_, settings_.certificate);
    out_.certificate_seconds += seconds_since(start);
    ++out_.certificates;
    const CoverageCertificate& c = out_.certificate;
    log::debug(
        "sampler round {}: covering radius <= {:.4f} r (>= {:.4f} r), {} of {} sub-triangles uncovered",
        out_.rounds, c.covering_bound / plan_.z.radius, c.covering_lower / plan_.z.radius, c.uncovered,
        c.evaluated);
  }

  // New particles at the deepest uncovered points, one per hole (already on the surface); only they
  // and the particles near them relax again, so the rest of the arrangement stays as it is.
  bool inject() {
    const std::vector<UncoveredPiece> holes = deepest_holes(
        out_.certificate, as_stored(out_.particles), std::max<std::size_t>(1, out_.particles.size() / 10));
    if (holes.empty()) return false;
    mobile_ = mobile_near_injections(out_.particles, holes, kMobileRadiusOverSpacing * plan_.z.spacing);
    for (const auto& hole : holes) out_.particles.push_back(hole.position);
    relax_.max_iterations = std::min(relax_.max_iterations, kLocalIterations);
    ++out_.rounds;
    return true;
  }

  ParticleRelaxer& relaxer_;
  Certifier& certifier_;
  const sdf::ExactDistance& exact_;
  const sdf::GridSpec& spec_;
  const SamplingPlan& plan_;
  const SampleSettings& settings_;
  const std::function<void(const SampleProgress&)>& progress_;
  const double target_;  // m, the covering radius to reach
  RelaxSettings relax_;
  std::vector<std::uint8_t> mobile_;
  Arrangement out_;
};

// What is reported of the coverage: the certificate at radius r (the rounds' own when they aimed at
// r, i.e. --coverage 1) and the covering radius over random probes, a second, statistical figure of
// the same particles. No probe can lie deeper than the certified bound: one that does means the
// certificate is wrong, a bug, and no body is written.
struct CoverageFigures {
  CoverageCertificate certificate;
  CoverageResult probes;
  int certificates = 0;              // computed, the rounds' included
  double certificate_seconds = 0.0;  // s, their wall time
  double probe_seconds = 0.0;        // s
};

CoverageFigures measure_coverage_figures(Certifier& certifier, const TriangleMesh& mesh, Arrangement& a,
                                         const SamplingPlan& plan, const SampleSettings& settings) {
  CoverageFigures f;
  const std::vector<Eigen::Vector3f> stored = as_stored(a.particles);
  auto start = std::chrono::steady_clock::now();
  f.certificates = a.certificates;
  if (settings.coverage == 1.0) {
    f.certificate = std::move(a.certificate);
  } else {
    f.certificate = certifier.certify(stored, plan.z.radius, settings.certificate);
    ++f.certificates;
  }
  f.certificate_seconds = a.certificate_seconds + seconds_since(start);
  start = std::chrono::steady_clock::now();
  CoverageSettings probe;
  probe.probes = probe_count(a.particles.size(), settings);
  probe.seed = settings.seed + 1000u * static_cast<unsigned>(a.rounds + 1) + 500u;
  f.probes = measure_coverage(mesh, std::span<const Eigen::Vector3f>(stored), probe);
  f.probe_seconds = seconds_since(start);
  if (f.probes.covering_radius > f.certificate.covering_bound) {
    const Eigen::Vector3d& p = f.probes.deepest.position;
    throw Error(
        ExitCode::Internal,
        fmt::format(
            "coverage certificate contradicted: a probe at ({:.9g}, {:.9g}, {:.9g}) m lies {:.9g} m from "
            "every particle, beyond the certified bound {:.9g} m",
            p.x(), p.y(), p.z(), f.probes.covering_radius, f.certificate.covering_bound));
  }
  return f;
}

void warn_about_quality(const CoverageFigures& f, int rounds, const SamplingPlan& plan,
                        const SampleSettings& settings, SampleResult& result) {
  const double r = plan.z.radius;
  const CoverageCertificate& c = f.certificate;
  if (c.covering_bound > settings.coverage * r) {
    result.warnings.push_back(fmt::format(
        "coverage target not certified after {} rounds: covering radius <= {:.4g} m = {:.3f} r (>= {:.3f} r; "
        "target {:.3f} r); {} sub-triangles ({:.3g} m^2) not proven within r of a particle{}",
        rounds, c.covering_bound, c.covering_bound / r, c.covering_lower / r, settings.coverage, c.uncovered,
        c.uncovered_area,
        result.holes.empty() ? std::string()
                             : fmt::format(", deepest hole {:.3f} r at ({:.6g}, {:.6g}, {:.6g}) m",
                                           result.holes[0].depth / r, result.holes[0].position.x(),
                                           result.holes[0].position.y(), result.holes[0].position.z())));
  }
  if (c.budget_reached) {
    result.warnings.push_back(
        "the coverage certificate reached its sub-triangle budget on a single triangle (one triangle alone "
        "needs more sub-triangles at one level than the budget): it stopped refining that triangle early "
        "(still conservative, but coarser)");
  }
  const ThinFeatures& thin = result.thin;
  if (thin.triangles > 0) {
    result.warnings.push_back(fmt::format(
        "{} triangles ({:.1f} % of the area, {} region{}) belong to features thinner than {} x the particle "
        "spacing {:.4g} m (within [{:.4g}, {:.4g}, {:.4g}] .. [{:.4g}, {:.4g}, {:.4g}] m): particles of both "
        "sides overlap there",
        thin.triangles, 100.0 * thin.area_share, thin.regions.size(), thin.regions.size() == 1 ? "" : "s",
        kThinOverSpacing, plan.z.spacing, thin.where.min.x(), thin.where.min.y(), thin.where.min.z(),
        thin.where.max.x(), thin.where.max.y(), thin.where.max.z()));
  }
}

// The particles (surface, then the interior fill), their radius and the solid's mass properties.
void fill_body(const Arrangement& a, const sdf::ExactDistance& exact, const TriangleMesh& mesh,
               const SamplingPlan& plan, const SampleSettings& settings, body::ParticleBody& body) {
  for (std::size_t i = 0; i < a.particles.size(); ++i) {
    body.positions.push_back(a.particles[i].cast<float>());
    body.normals.push_back(a.normals[i].cast<float>());
  }
  if (settings.fill) {
    const std::vector<Eigen::Vector3d> interior =
        fill_interior(exact, bounding_box(mesh), plan.mass.center_of_mass, plan.z.radius, settings.sign);
    for (const auto& p : interior) {
      body.positions.push_back(p.cast<float>());
      body.normals.push_back(Eigen::Vector3f::Zero());
    }
    body.interior_count = interior.size();
  }
  body.particle_radius = plan.z.radius;
  set_mass_properties(body, plan.mass);
  if (settings.mass_method == body::MassMethod::WindingCells) {
    body.mass_method = body::MassMethod::WindingCells;
    body.mass_cell = plan.mass_cell;
  }
}

// Quality figures of the surface particles alone (docs/body-format.md).
body::ParticleBody::Quality measure_quality(const Arrangement& a, const CoverageFigures& f,
                                            const TriangleMesh& mesh, const SamplingPlan& plan,
                                            const SampleSettings& settings) {
  const std::span<const Eigen::Vector3d> particles(a.particles);
  const SpacingStatistics spacing = spacing_statistics(plan.area, particles);
  const double r = plan.z.radius;
  const double c = f.probes.covering_radius;
  body::ParticleBody::Quality q;
  q.relative_radius = spacing.relative_radius;
  q.cv = spacing.cv_nn;
  q.covering_radius = c;
  q.covering_over_r = c / r;
  if (settings.grain_radius > 0.0) q.covering_over_r_plus_grain = c / (r + settings.grain_radius);
  q.max_abs_phi_over_r = max_distance_to_surface(mesh, particles) / r;
  q.iterations = a.iterations;
  q.injection_rounds = a.rounds;
  q.converged = a.converged;
  const CoverageCertificate& cert = f.certificate;
  q.certificate = body::ParticleBody::Quality::Certificate{
      cert.covered,   cert.covering_bound / r, cert.covering_lower / r,
      cert.uncovered, cert.uncovered_area,     cert.floor};
  return q;
}

// The --timings table of host-GPU round trips: the scan conversion, the relaxer's phases, and the
// whole run since `start` (the certificate's passes and the rest).
std::string round_trip_report(const gpu::HostSyncCounts& scan, const ParticleRelaxer& relaxer,
                              const gpu::HostSyncCounts& start) {
  std::vector<gpu::HostSyncPhase> phases{{"SDF scan conversion", scan, 0, ""}};
  for (gpu::HostSyncPhase& phase : relaxer.round_trips()) phases.push_back(std::move(phase));
  phases.push_back({"sample in all (with the certificate's passes)", gpu::host_sync_counts() - start, 0, ""});
  return gpu::host_sync_report(phases);
}

}  // namespace

SdfPath choose_sdf_path(const gpu::Context* context, const SampleSettings& settings) {
  if (settings.cpu_sdf == CpuSdfMethod::OpenVdb) {
    if (settings.sign != sdf::SignMethod::Pseudonormal) {
      throw InputError("--sdf-backend openvdb signs the field by OpenVDB's own flood fill, which needs a closed "
                       "mesh: with --sign winding use --sdf-backend cpu or gpu");
    }
    return SdfPath::OpenVdb;
  }
  // Without a GL context the rule gives the CPU: the field can only come from there.
  return gpu::resolve_backend(settings.sdf_backend, context) == gpu::Backend::Gpu ? SdfPath::Scan : SdfPath::Exact;
}

const char* sdf_path_name(SdfPath path) {
  switch (path) {
    case SdfPath::Exact:
      return "cpu";
    case SdfPath::OpenVdb:
      return "openvdb";
    case SdfPath::Scan:
      break;
  }
  return "gpu";
}

std::size_t probe_count(std::size_t particles, const SampleSettings& settings) {
  const std::size_t cap = std::max<std::size_t>(settings.probes, 1);
  if (settings.probes_per_particle == 0) return cap;
  const std::size_t wanted = particles > cap / settings.probes_per_particle
                                 ? cap
                                 : std::max(kMinProbes, settings.probes_per_particle * particles);
  return std::min(cap, wanted);
}

SampleResult sample_mesh(gpu::Context* context, const TriangleMesh& mesh, const SampleSettings& settings,
                         const std::function<void(const SampleProgress&)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const gpu::HostSyncCounts syncs_at_start = gpu::host_sync_counts();
  SampleResult result;
  StageSeconds& t = result.stages;
  auto lap = std::chrono::steady_clock::now();
  const auto stage = [&lap](double& total) {
    total += seconds_since(lap);
    lap = std::chrono::steady_clock::now();
  };
  // Validate and size (every check before the GPU work).
  if (!(surface_area(mesh) > 0.0)) throw InputError("the mesh has no surface area");
  const sdf::ExactDistance exact(mesh);
  const SamplingPlan plan = plan_sampling(mesh, exact, settings, result);
  stage(t.plan);
  // The field, and seeds spread over the surface.
  const sdf::GridSpec spec = choose_grid(mesh, plan.z.radius, settings);
  result.relax_on_cpu = relax_on_cpu(context, settings);
  RelaxField field = make_field(context, mesh, exact, spec, plan, settings, result);
  const gpu::HostSyncCounts scan_syncs = gpu::host_sync_counts() - syncs_at_start;
  stage(t.sdf);
  std::mt19937_64 rng(settings.seed);
  std::vector<Eigen::Vector3d> seeds = sample_surface_points(mesh, plan.z.count, rng).positions;
  // Relax and close holes.
  const std::unique_ptr<ParticleRelaxer> relaxer = make_relaxer(context, std::move(field), settings.timings);
  const std::unique_ptr<Certifier> certifier = make_certifier(context, mesh, settings, result);
  stage(t.setup);
  Arrangement a =
      HoleClosing(*relaxer, *certifier, exact, spec, plan, settings, progress).run(std::move(seeds));
  t.relaxation = a.relax_seconds, t.projection = a.projection_seconds, t.injection = a.injection_seconds;
  lap = std::chrono::steady_clock::now();
  // Measure and make the body.
  CoverageFigures coverage = measure_coverage_figures(*certifier, mesh, a, plan, settings);
  t.certificate = coverage.certificate_seconds, t.probes = coverage.probe_seconds;
  result.probes = coverage.probes.probes;
  lap = std::chrono::steady_clock::now();
  body::ParticleBody& body = result.body;
  body.quality = measure_quality(a, coverage, mesh, plan, settings);
  const auto thin_start = std::chrono::steady_clock::now();
  result.thin = find_thin_features(mesh, exact, plan.z.spacing, plan.z.radius);
  t.thin_features = seconds_since(thin_start);
  result.holes = deepest_holes(coverage.certificate, as_stored(a.particles), kReportedHoles);
  warn_about_quality(coverage, a.rounds, plan, settings, result);
  result.certificate = std::move(coverage.certificate);
  result.certificate_passes = coverage.certificates;
  result.certificate_seconds = coverage.certificate_seconds;
  result.probe_seconds = coverage.probe_seconds;
  if (settings.sign == sdf::SignMethod::Winding) orient_normals_by_winding(exact, a.particles, a.normals, plan.z.radius);
  fill_body(a, exact, mesh, plan, settings, body);
  body.sdf_voxel_size = spec.voxel_size;
  stage(t.body);
  t.body -= t.thin_features;
  body.quality.seconds = seconds_since(start);
  if (settings.timings) {
    result.timing_report += relaxer->timing_report() + certifier->timing_report();
    result.timing_report += round_trip_report(scan_syncs, *relaxer, syncs_at_start);
  }
  return result;
}

void check_sample_mesh(const TriangleMesh& mesh, const std::string& name, bool winding, SampleSettings& settings) {
  const MeshReport report = analyze_mesh(mesh);
  settings.sign = winding ? sdf::SignMethod::Winding : sdf::SignMethod::Pseudonormal;
  if (report.watertight()) return;
  if (!winding) {
    throw InputError(name,
                     "is not a closed, consistently oriented solid (" + closed_solid_problems(report) +
                         "); `tetrasand info` shows the full report; --sign winding samples it anyway\n" +
                         format_report(report));
  }
  log::warn(
      "{}: not a closed solid ({}): sampled with winding-number signs; the particles cover the mesh's own "
      "surface only (holes stay open), mass properties come from the winding-number solid",
      name, closed_solid_problems(report));
  settings.mass_method = body::MassMethod::WindingCells;
}

}  // namespace ts::sampler
