#pragma once
// The GPU half of the repulsion sampler: relaxes particles on the zero level set of an SDF held in a
// 3D texture, with neighbours from a hashed grid rebuilt every step (thesis 6.3). Seeding, coverage
// repair and output live in sampler/sample_mesh.h; this class only moves particles.
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/hash_grid.h"
#include "gpu/host_sync.h"
#include "sdf/scan_convert.h"
#include "sdf/sparse_field.h"

namespace ts::sampler {

struct RelaxSettings {
  double spacing = 0.0;             // target distance between neighbours [m] (the hexagonal spacing)
  double sigma_over_spacing = 0.45;  // Gaussian width; formulas.md: 0.4-0.5 d_hex relaxes best
  // Kernel cut-off: exp(-R^2 / (2 sigma^2)) = kernel_epsilon, i.e. R = sigma sqrt(2 ln(1/eps))
  // (thesis appendix A.2 with A = 1). The hashed grid's cell equals R, so 27 cells hold all neighbours.
  double kernel_epsilon = 1e-3;
  double repulsion_gain = 0.5;       // step on the kernel sum (dimensionless)
  // Heavy-ball momentum on the tangential step (see shaders/sampler/relax.comp): 0 = plain descent.
  double momentum = 0.8;
  double max_move_over_cell = 0.25;  // CFL guard: no particle moves more than this fraction of a cell
  double band_limit = 0.0;           // |phi| at which a particle has left the band [m]
  int max_iterations = 2000;
  // Convergence read back every k steps: each check drains the GPU's queue (a host round trip), the
  // steps between make none. See docs/architecture.md for the measured cost of the check.
  int check_every = 10;
  // Converged when the mean gradient step of the mobile particles (gain * tangential repulsion minus
  // phi n, the move plain descent would make) is below tolerance * spacing. Measured floor: 1.9e-4 to
  // 2.5e-4 on llvmpipe (sphere, torus, trefoil, bunny), set by the 8-bit weights of hardware trilinear
  // filtering that tilt the tangent plane; rho and CV stop changing well above it (bunny, 1000
  // particles: rho 0.68, CV 0.042-0.044 from 200 to 1000 steps).
  double tolerance = 5e-4;
  int projection_steps = 4;          // final p <- p - phi grad(phi) iterations
};

struct RelaxStats {
  int iterations = 0;
  int checks = 0;  // convergence checks read back: ceil(iterations / check_every) unless converged early
  bool converged = false;
  double mean_move_over_spacing = 0.0;  // at the last check
  std::size_t removed = 0;              // left the band and were dropped
};

class GpuRelaxer {
 public:
  // Takes the sparse SDF already on the GPU (sdf::SparseField: trilinear distance, central-difference
  // gradient); nothing is uploaded.
  GpuRelaxer(gpu::Context& context, sdf::SparseField field, bool timings = false);
  GpuRelaxer(const GpuRelaxer&) = delete;
  GpuRelaxer& operator=(const GpuRelaxer&) = delete;

  // Positions are relative to the SDF's voxel (0,0,0) centre [m]; on return they are relaxed and
  // projected, without the particles that left the band. `progress(iteration, count, residual)`.
  // `mobile` (optional, one flag per particle, compacted alongside on removal): only flagged particles
  // move; the others stay put but still repel.
  RelaxStats relax(std::vector<Eigen::Vector3f>& positions, const RelaxSettings& settings,
                   const std::function<void(int, std::size_t, double)>& progress = {},
                   std::vector<std::uint8_t>* mobile = nullptr);

  std::string timing_report() { return queue_.timing_report(); }
  // Host-GPU round trips by phase over every relax() so far (gpu/host_sync.h): the iterations
  // between checks (none, by design), the checks, and all of relax() (with uploads, band removals
  // and the results read back).
  std::vector<gpu::HostSyncPhase> round_trips() const;
  std::size_t gpu_bytes() const;

 private:
  void bind_sdf(const gpu::Program& program) const;
  void project(std::uint32_t count, int steps);
  // One step: the hashed grid rebuilt, every particle moved (no read-back).
  void iterate(std::uint32_t count, double cutoff);
  // The convergence reduction, read back: one host round trip.
  struct StepSums {
    double moved = 0.0, outside = 0.0, moving = 0.0;
  };
  StepSums check(std::uint32_t count);
  gpu::Context& context_;
  sdf::GridSpec spec_;
  sdf::SparseField field_;
  gpu::ShaderLibrary library_;
  gpu::Queue queue_;
  gpu::Program relax_, project_, reduce_;
  gpu::HashGrid grid_;
  gpu::Buffer positions_[2], velocities_, step_info_, partials_;
  gpu::HostSyncCounts iteration_syncs_, check_syncs_, relax_syncs_;
  std::int64_t iterations_run_ = 0, checks_run_ = 0;
};

}  // namespace ts::sampler
