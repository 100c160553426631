#pragma once
// The repulsion sampler's relaxation as GL compute kernels (sampler/relaxer.h): particles on the zero
// level set of the sparse SDF on the GPU, neighbours from a hashed grid rebuilt every step (thesis
// 6.3). sampler/cpu_relaxer.h is the same algorithm on the CPU.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/hash_grid.h"
#include "gpu/host_sync.h"
#include "sampler/relaxer.h"
#include "sdf/gpu_field.h"
#include "sdf/scan_convert.h"
#include "sdf/sparse_field.h"

namespace ts::sampler {

class GpuRelaxer final : public ParticleRelaxer {
 public:
  // Takes the SDF already on the GPU (sdf::SparseField uploaded from the host, or sdf::LeafField built
  // there by the scan conversion: trilinear distance, central-difference gradient, the same reads);
  // nothing is uploaded.
  GpuRelaxer(gpu::Context& context, std::unique_ptr<const sdf::GpuField> field, bool timings = false);
  GpuRelaxer(gpu::Context& context, sdf::SparseField field, bool timings = false)
      : GpuRelaxer(context, std::make_unique<const sdf::SparseField>(std::move(field)), timings) {}
  GpuRelaxer(const GpuRelaxer&) = delete;
  GpuRelaxer& operator=(const GpuRelaxer&) = delete;

  std::string timing_report() override { return queue_.timing_report(); }
  // The iterations between checks make none, by design; each check one; all of relax() adds the
  // uploads, the band removals and the results read back.
  std::vector<gpu::HostSyncPhase> round_trips() const override;
  std::size_t gpu_bytes() const;

 private:
  RelaxStats run(std::vector<Eigen::Vector3f>& positions, const RelaxSettings& settings,
                 const RelaxProgress& progress, std::vector<std::uint8_t>* mobile) override;
  void bind_sdf() const;
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
  std::unique_ptr<const sdf::GpuField> field_;
  gpu::ShaderLibrary library_;
  gpu::Queue queue_;
  gpu::Program relax_, project_, reduce_;
  gpu::ParamBlock<gpu::params::RelaxParams> relax_params_;  // the step's constants, set once per run
  gpu::ParamBlock<gpu::params::ItemCount> count_params_;    // project_ and reduce_
  gpu::HashGrid grid_;
  gpu::Buffer positions_[2], velocities_, step_info_, partials_;
  gpu::HostSyncCounts iteration_syncs_, check_syncs_, relax_syncs_;
  std::int64_t iterations_run_ = 0, checks_run_ = 0;
};

}  // namespace ts::sampler
