#pragma once
// The repulsion sampler's relaxation (thesis 6.3), whatever runs it: particles near the zero level
// set of a narrow-band SDF are spread evenly over it by Gaussian repulsion, attracted to it by
// -phi grad(phi) and projected onto it at the end. sampler/gpu_relaxer.h runs it as GL compute kernels
// (shaders/sampler/relax.comp, project.comp, reduce_steps.comp); sampler/cpu_relaxer.h runs the same
// algorithm on the CPU with TBB. sample_mesh picks one (SampleSettings::backend, by the rule of
// gpu/backend.h). Seeding, coverage repair and output live in sampler/sample_mesh.h; a relaxer only
// moves particles.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "gpu/host_sync.h"

namespace ts::sampler {

struct RelaxSettings {
  double spacing = 0.0;              // target distance between neighbours [m] (the hexagonal spacing)
  double sigma_over_spacing = 0.45;  // Gaussian width; formulas.md: 0.4-0.5 d_hex relaxes best
  // Kernel cut-off: exp(-R^2 / (2 sigma^2)) = kernel_epsilon, i.e. R = sigma sqrt(2 ln(1/eps))
  // (thesis appendix A.2 with A = 1). The hashed grid's cell equals R, so 27 cells hold all neighbours.
  double kernel_epsilon = 1e-3;
  double repulsion_gain = 0.5;  // step on the kernel sum (dimensionless)
  // Heavy-ball momentum on the tangential step (see shaders/sampler/relax.comp): 0 = plain descent.
  double momentum = 0.8;
  double max_move_over_cell = 0.25;  // CFL guard: no particle moves more than this fraction of a cell
  double band_limit = 0.0;           // |phi| at which a particle has left the band [m]
  int max_iterations = 2000;
  // Convergence read back every k steps: each check drains the GPU's queue (a host round trip), the
  // steps between make none. See docs/architecture.md for the measured cost of the check.
  int check_every = 10;
  // Converged when the mean gradient step of the mobile particles (gain * tangential repulsion minus
  // phi n, the move plain descent would make) is below tolerance * spacing. The floor was measured at
  // 1.9e-4 to 2.5e-4 on llvmpipe (sphere, torus, trefoil, bunny) when the field was a dense texture read
  // through hardware trilinear filtering, whose 8-bit weights tilt the tangent plane; since cfe0017 the
  // field is read in full float and the floor has not been measured again. rho and CV stop changing well
  // above the tolerance (bunny, 1000 particles: rho 0.68, CV 0.042-0.044 from 200 to 1000 steps), and a
  // 4x looser one visibly cuts evenness (SampleMesh.EvennessOnAThinFeaturedCgalMeshHoldsAcrossSeeds).
  double tolerance = 5e-4;
  int projection_steps = 4;  // final p <- p - phi grad(phi) iterations
};

struct RelaxStats {
  int iterations = 0;
  int checks = 0;  // convergence checks read back: ceil(iterations / check_every) unless converged early
  bool converged = false;
  double mean_move_over_spacing = 0.0;  // at the last check
  std::size_t removed = 0;              // left the band and were dropped
};

// `progress(iteration, count, residual)` after each convergence check.
using RelaxProgress = std::function<void(int, std::size_t, double)>;

class ParticleRelaxer {
 public:
  virtual ~ParticleRelaxer() = default;

  // Positions are relative to the SDF's voxel (0,0,0) centre [m]; on return they are relaxed and
  // projected, without the particles that left the band (the others in their order). `mobile`
  // (optional, one flag per particle, compacted alongside on removal): only flagged particles move;
  // the others stay put but still repel.
  RelaxStats relax(std::vector<Eigen::Vector3f>& positions, const RelaxSettings& settings,
                   const RelaxProgress& progress = {}, std::vector<std::uint8_t>* mobile = nullptr) {
    return run(positions, settings, progress, mobile);
  }

  // Per-kernel GPU times (with timings on), or the CPU's stage times.
  virtual std::string timing_report() = 0;
  // Host-GPU round trips by phase over every relax() so far (gpu/host_sync.h): the iterations between
  // checks, the checks, and all of relax(). All zero on the CPU (no GPU is involved).
  virtual std::vector<gpu::HostSyncPhase> round_trips() const = 0;

 protected:
  ParticleRelaxer() = default;
  ParticleRelaxer(const ParticleRelaxer&) = delete;
  ParticleRelaxer& operator=(const ParticleRelaxer&) = delete;

 private:
  virtual RelaxStats run(std::vector<Eigen::Vector3f>& positions, const RelaxSettings& settings,
                         const RelaxProgress& progress, std::vector<std::uint8_t>* mobile) = 0;
};

}  // namespace ts::sampler
