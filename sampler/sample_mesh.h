#pragma once
// The main job: a closed mesh becomes a particle rigid body (thesis 6.3; Bell, Yu & Mucha 2005).
//   1. SDF by GPU scan conversion (or exact CPU distance: sdf_backend), voxel = r / 2 unless set
//      (see SampleSettings::voxel_size);
//   2. seeds spread area-uniformly with the injected seed, as many as the coverage target needs;
//   3. relaxation (attraction to the zero level set + Gaussian repulsion) on the GPU or the CPU
//      (SampleSettings::backend; sampler/relaxer.h);
//   4. exact projection onto the mesh, crowded pairs (closer than 0.6 spacing) thinned, coverage
//      certified (sampler/gpu_coverage_certificate.h), particles injected at the deepest
//      uncovered points it proves; the first 3 rounds relax them with their neighbours (the rest
//      frozen), later ones only place them, until the certificate holds or the round limit;
//   5. quality figures: the certificate at radius r, and the covering radius over random surface
//      probes as a second, statistical figure; mass properties (from the closed mesh, never from the
//      particles; for a mesh that encloses no volume by itself, from its winding-number solid:
//      sampler/winding_solid.h).
#include <functional>
#include <string>
#include <vector>

#include "body/particle_body.h"
#include "core/mesh.h"
#include "gpu/backend.h"
#include "gpu/context.h"
#include "sampler/gpu_coverage_certificate.h"
#include "sampler/relaxer.h"
#include "sampler/thin_features.h"
#include "sdf/settings.h"

namespace ts::sampler {

// Where each stage runs follows the one rule of gpu/backend.h (gpu::Backend; auto: the CPU on a
// software renderer or without a GL context, the GPU on a hardware device):
// - the SDF (SampleSettings::sdf_backend): GPU scan conversion (sdf/scan_convert.h), or on the CPU by
//   `cpu_sdf` (below). On llvmpipe the scan conversion's geometry and fragment work runs on the same
//   cores; the exact sweep is also faster than OpenVDB at every size measured, the 1M-particle bunny's
//   band in 12 s (docs/benchmarks.md, "sample fixed costs").
// - the relaxation and the coverage certificate (SampleSettings::backend): GL compute kernels
//   (sampler/gpu_relaxer.h, sampler/gpu_coverage_certificate.h) or the same algorithms on the CPU with TBB
//   (sampler/cpu_relaxer.h, sampler/cpu_coverage_certificate.h). llvmpipe runs the kernels on the same
//   cores, with a fixed cost per dispatch that small counts do not amortise and a 128 MiB storage block
//   that stops the sparse field of a 10^6-particle body (docs/benchmarks.md, "sample fixed costs").

// The method of a field built on the CPU: exact distance (sdf::exact_sdf_grid: a sweep over the
// triangles, TBB), or OpenVDB's meshToVolume (sdf::openvdb_index_level_set; approximate, about 0.01
// voxel on average and a few wrong signs next to the surface, docs/benchmarks.md "SDF"; closed meshes
// only). OpenVdb is a CPU method: it takes the CPU whatever sdf_backend says.
enum class CpuSdfMethod { Exact, OpenVdb };
// What built a run's field.
enum class SdfPath { Scan, Exact, OpenVdb };
// "gpu", "cpu", "openvdb": the --sdf-backend value that names the path.
const char* sdf_path_name(SdfPath path);

struct SampleSettings {
  double radius = 0.0;         // particle radius r [m]; 0: from `count`, else about 8000 particles
  std::size_t count = 0;       // particle count instead of a radius
  double coverage = 1.0;       // target covering radius / r: 1 = the spheres cover the whole surface
  double grain_radius = 0.0;   // grain radius [m] for the leak figure c / (r + r_grain); 0: not reported
  double voxel_size = 0.0;     // SDF voxel [m]; 0: r / 2, so trilinear interpolation error stays far below r
  double density = 1000.0;     // kg/m^3
  std::uint64_t seed = 1;
  int max_rounds = 12;                 // coverage repair rounds
  // Random surface points of the statistical covering radius: probes_per_particle per particle, at
  // least kMinProbes, at most `probes` (sampler::probe_count; the miss bound is in
  // docs/coverage-certificate.md, "The probe pass"). probes_per_particle 0: always `probes`.
  std::size_t probes = 1'000'000;
  std::size_t probes_per_particle = 256;
  gpu::Backend sdf_backend = gpu::Backend::Auto;   // the field's device
  sdf::ScanMethod scan = sdf::ScanMethod::Geometry;  // the GPU scan conversion's method (sample --scan)
  CpuSdfMethod cpu_sdf = CpuSdfMethod::Exact;       // the field's method on the CPU
  gpu::Backend backend = gpu::Backend::Auto;       // the relaxation's and the certificate's device
  // The coverage certificate that steers the rounds and is reported (floor: r / floor_divisor).
  CertificateSettings certificate;
  std::size_t max_particles = 20'000'000;
  // Sparse SDF budget [bytes], GPU memory (host memory on the CPU path): past it the run stops (exit 1).
  std::size_t max_sdf_bytes = 1ull << 30;
  // Inside and outside (particle normals, thin features, interior fill): pseudonormals need a closed,
  // consistently oriented mesh; the generalised winding number also works on open or non-manifold
  // ones (normals then point to where the winding number drops).
  sdf::SignMethod sign = sdf::SignMethod::Pseudonormal;
  // Mass, centre of mass and inertia: of the closed mesh (divergence theorem), or integrated over the
  // winding-number solid (octree, sampler/winding_solid.h) when the mesh encloses no volume by itself.
  body::MassMethod mass_method = body::MassMethod::ClosedMesh;
  double mass_cell = 0.0;              // finest octree cell of MassMethod::WindingCells [m]; 0: longest side / 128
  // Also interior particles on a lattice (sampler/interior_fill.h: FCC, spacing 2 r, centres at
  // phi <= -r), appended after the surface ones with zero normals. Default: surface only.
  bool fill = false;
  bool timings = false;
  RelaxSettings relax;                 // spacing and band are filled in from the radius
};

struct SampleProgress {
  int round = 0;               // 0: first relaxation; k: after the k-th injection
  int iteration = 0;
  std::size_t particles = 0;
  double residual = 0.0;       // mean displacement per step / spacing
};

// The probe pass's size for `particles` surface particles: min(probes, max(kMinProbes,
// probes_per_particle * particles)), or `probes` when probes_per_particle is 0.
inline constexpr std::size_t kMinProbes = std::size_t{1} << 16;
std::size_t probe_count(std::size_t particles, const SampleSettings& settings);

// Wall time of each stage of sample_mesh [s] (the --timings table and --json's "stages").
struct StageSeconds {
  double plan = 0.0;           // validation, the exact-distance tree, sizing, mass properties
  double sdf = 0.0;    // the field: scan conversion (or exact CPU distance), NanoVDB, upload (GPU path)
  double setup = 0.0;  // seeds, the relaxer's and the certifier's programs and buffers (GPU path)
  double relaxation = 0.0;     // every relax() call, all rounds
  double projection = 0.0;     // exact projection and thinning, all rounds
  double certificate = 0.0;    // every certificate pass
  double injection = 0.0;      // choosing the holes' new particles, all rounds
  double probes = 0.0;         // the statistical probe pass
  double thin_features = 0.0;  // find_thin_features
  double body = 0.0;           // quality figures, holes, normals, interior fill, mass properties
};

// Most holes a SampleResult lists (the deepest; a certificate may prove more).
inline constexpr std::size_t kReportedHoles = 20;

// What the sparse SDF cost (docs/benchmarks.md reports it per band voxel).
struct FieldStats {
  std::size_t band_voxels = 0;          // voxels with |d| < band
  sdf::ScanMethod scan = sdf::ScanMethod::Geometry;  // the scan conversion's method (SdfPath::Scan)
  std::size_t gpu_bytes = 0;            // the field on the GPU (the leaf field, or the uploaded NanoVDB grid)
  bool gpu_resident = false;            // built and kept on the GPU by the scan (sdf::LeafField): no round trip
  std::size_t host_bytes = 0;           // the OpenVDB level set and the NanoVDB grid on the host, at their peak
  std::size_t readback_bytes = 0;       // field bytes GPU -> host between the scan and the relaxation (the
                                        // compacted band on the host path; 0 on the GPU-resident one)
  std::size_t scan_peak_gpu_bytes = 0;  // scan conversion's slab target and buffers
};

struct SampleResult {
  body::ParticleBody body;
  ThinFeatures thin;                // features thinner than the spacing, by region (sampler/thin_features.h)
  std::size_t estimated_count = 0;  // surface particles, from the area and the coverage target
  double estimated_interior = 0.0;  // with `fill`: lattice points in V(phi <= -r) ~ V - A r, / (4 sqrt(2) r^3)
  CoverageCertificate certificate;  // of the surface particles at radius r (body.quality has its figures)
  std::vector<UncoveredPiece> holes;  // deepest uncovered points, one per hole, deepest first (<= kReportedHoles)
  int certificate_passes = 0;         // certificates computed, all rounds
  double certificate_seconds = 0.0;   // s, wall time of those
  double probe_seconds = 0.0;         // s, wall time of the statistical probe pass
  std::size_t probes = 0;             // surface points of that pass (probe_count)
  SdfPath sdf_path = SdfPath::Scan;   // which path built the field (sdf_backend, cpu_sdf)
  bool relax_on_cpu = false;          // the relaxation ran on the CPU (backend)
  bool certificate_on_cpu = false;    // the coverage certificate ran on the CPU (backend)
  StageSeconds stages;
  std::vector<std::string> warnings;
  FieldStats field;
  std::string timing_report;

  bool sdf_on_cpu() const { return sdf_path != SdfPath::Scan; }  // exact or OpenVDB's
};

// The path that builds the field under `settings` with `context` (null: none): gpu::resolve_backend of
// sdf_backend, then cpu_sdf on the CPU. Throws InputError for OpenVDB with the winding-number sign.
SdfPath choose_sdf_path(const gpu::Context* context, const SampleSettings& settings);

// `context` may be null when no stage needs the GPU: backend Cpu or Auto (then the CPU), and
// sdf_backend Cpu or Auto or cpu_sdf OpenVdb (then a CPU field); a GPU stage without one is an internal
// error.
SampleResult sample_mesh(gpu::Context* context, const TriangleMesh& mesh, const SampleSettings& settings,
                         const std::function<void(const SampleProgress&)>& progress = {});

// Whether `mesh` can be sampled, and the sign and mass methods it allows (sets settings.sign and
// settings.mass_method): a closed, consistently oriented solid takes `winding` as asked; any other mesh
// is refused (InputError naming `name`, with the mesh report) unless `winding`, and is then sampled from
// its winding-number solid with a warning. The one check of `tetrasand sample` and the Python module.
void check_sample_mesh(const TriangleMesh& mesh, const std::string& name, bool winding, SampleSettings& settings);

inline SampleResult sample_mesh(gpu::Context& context, const TriangleMesh& mesh,
                                const SampleSettings& settings,
                                const std::function<void(const SampleProgress&)>& progress = {}) {
  return sample_mesh(&context, mesh, settings, progress);
}

}  // namespace ts::sampler
