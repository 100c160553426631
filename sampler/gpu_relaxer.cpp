#include "sampler/gpu_relaxer.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "shaders/common/bindings.h"
#include "shaders/sampler/bindings.h"

namespace ts::sampler {

namespace {

const sdf::GpuField& required(const std::unique_ptr<const sdf::GpuField>& field) {
  if (!field || field->empty()) throw Error(ExitCode::Internal, "GpuRelaxer needs a field on the GPU");
  return *field;
}

}  // namespace

GpuRelaxer::GpuRelaxer(gpu::Context& context, std::unique_ptr<const sdf::GpuField> field, bool timings)
    : context_(context),
      spec_(required(field).spec()),
      field_(std::move(field)),
      queue_(timings, context.debug()),
      relax_(gpu::Program::compute(library_, "sampler/relax.comp", field_->shader_defines())),
      project_(gpu::Program::compute(library_, "sampler/project.comp", field_->shader_defines())),
      reduce_(gpu::Program::compute(library_, "sampler/reduce_steps.comp")),
      grid_(library_) {}

std::size_t GpuRelaxer::gpu_bytes() const {
  return field_->gpu_bytes() + positions_[0].bytes() * 2 + step_info_.bytes() + partials_.bytes() + grid_.bytes();
}

void GpuRelaxer::bind_sdf() const {
  field_->bind({TS_SAMPLER_SPARSE_FIELD,
               {TS_SAMPLER_FIELD_CHUNK_1, TS_SAMPLER_FIELD_CHUNK_2, TS_SAMPLER_FIELD_CHUNK_3, TS_SAMPLER_FIELD_CHUNK_4,
                TS_SAMPLER_FIELD_CHUNK_5, TS_SAMPLER_FIELD_CHUNK_6, TS_SAMPLER_FIELD_CHUNK_7},
               TS_SAMPLER_FIELD_PARAMS, TS_SAMPLER_FIELD_ROOTS});
}

void GpuRelaxer::project(std::uint32_t count, int steps) {
  positions_[0].bind(TS_SAMPLER_POSITIONS);
  bind_sdf();
  count_params_.values.count.x = count;
  count_params_.bind(TS_SAMPLER_PARAMS);
  for (int s = 0; s < steps; ++s) queue_.dispatch_items(project_, count);
}

void GpuRelaxer::iterate(std::uint32_t count, double cutoff) {
  const gpu::HostSyncScope counted(iteration_syncs_);
  ++iterations_run_;
  grid_.build(queue_, positions_[0], count, static_cast<float>(cutoff));
  positions_[0].bind(TS_SAMPLER_POSITIONS_IN);
  positions_[1].bind(TS_SAMPLER_POSITIONS_OUT);
  grid_.bind();
  velocities_.bind(TS_SAMPLER_VELOCITIES);
  step_info_.bind(TS_SAMPLER_STEP_INFO);
  bind_sdf();
  relax_params_.values.sizes = {count, grid_.table_size(), 0u, 0u};
  relax_params_.bind(TS_SAMPLER_PARAMS);
  queue_.dispatch_items(relax_, count);
  std::swap(positions_[0], positions_[1]);
}

GpuRelaxer::StepSums GpuRelaxer::check(std::uint32_t count) {
  const gpu::HostSyncScope counted(check_syncs_);
  ++checks_run_;
  step_info_.bind(TS_SAMPLER_STEP_INFO);
  partials_.bind(TS_SAMPLER_PARTIALS);
  count_params_.values.count.x = count;
  count_params_.bind(TS_SAMPLER_PARAMS);
  queue_.dispatch_items(reduce_, count);
  StepSums sums;
  for (const auto& p : partials_.read<Eigen::Vector4f>((count + 255) / 256)) {
    sums.moved += p.x(), sums.outside += p.z(), sums.moving += p.w();
  }
  return sums;
}

std::vector<gpu::HostSyncPhase> GpuRelaxer::round_trips() const {
  return {{"relaxation iterations between checks", iteration_syncs_, iterations_run_, "iteration"},
          {"convergence checks", check_syncs_, checks_run_, "check"},
          {"relaxation in all (uploads, band removals, results)", relax_syncs_, 0, ""}};
}

RelaxStats GpuRelaxer::run(std::vector<Eigen::Vector3f>& positions, const RelaxSettings& settings,
                           const RelaxProgress& progress, std::vector<std::uint8_t>* mobile) {
  if (!(settings.spacing > 0.0)) throw InputError("sampler spacing must be positive");
  if (mobile && mobile->size() != positions.size()) throw Error(ExitCode::Internal, "relax: mobile mask size");
  const gpu::HostSyncScope counted(relax_syncs_);
  const double sigma = settings.sigma_over_spacing * settings.spacing;
  const double cutoff = sigma * std::sqrt(2.0 * std::log(1.0 / settings.kernel_epsilon));
  RelaxStats stats;
  auto upload = [&] {
    const std::size_t n = std::max<std::size_t>(positions.size(), 1);
    std::vector<Eigen::Vector4f> packed(n, Eigen::Vector4f::Zero());
    for (std::size_t i = 0; i < positions.size(); ++i) {
      packed[i] << positions[i], (mobile == nullptr || (*mobile)[i]) ? 1.0f : 0.0f;
    }
    if (positions_[0].bytes() < n * 16) {
      positions_[0] = gpu::Buffer(n * 16);
      positions_[1] = gpu::Buffer(n * 16);
      velocities_ = gpu::Buffer(n * 16);
      step_info_ = gpu::Buffer(n * 16);
      partials_ = gpu::Buffer(((n + 255) / 256) * 16);
    }
    positions_[0].upload(packed.data(), n * 16);
    velocities_.fill_zero();
  };
  auto download = [&](std::uint32_t count) {
    const auto packed = positions_[0].read<Eigen::Vector4f>(count);
    positions.resize(count);
    for (std::uint32_t i = 0; i < count; ++i) positions[i] = packed[i].head<3>();
  };
  upload();
  std::uint32_t count = static_cast<std::uint32_t>(positions.size());

  relax_params_.values.kernel = {static_cast<float>(cutoff), static_cast<float>(1.0 / (2.0 * sigma * sigma)),
                                 static_cast<float>(settings.repulsion_gain), static_cast<float>(settings.momentum)};
  relax_params_.values.limits = {static_cast<float>(settings.max_move_over_cell * cutoff),
                                 static_cast<float>(settings.band_limit), 0.0f, 0.0f};
  while (stats.iterations < settings.max_iterations && count > 0) {
    iterate(count, cutoff);
    ++stats.iterations;
    if (stats.iterations % settings.check_every != 0 && stats.iterations < settings.max_iterations) continue;

    ++stats.checks;
    const StepSums sums = check(count);
    stats.mean_move_over_spacing = sums.moving > 0.0 ? sums.moved / sums.moving / settings.spacing : 0.0;
    if (progress) progress(stats.iterations, count, stats.mean_move_over_spacing);
    if (sums.outside > 0.0) {
      // Drop particles that left the band (rare: seeds start on the surface), on the CPU.
      const auto info = step_info_.read<Eigen::Vector4f>(count);
      download(count);
      std::size_t kept = 0;
      for (std::uint32_t i = 0; i < count; ++i) {
        if (info[i].z() != 0.0f) continue;
        if (mobile) (*mobile)[kept] = (*mobile)[i];
        positions[kept++] = positions[i];
      }
      stats.removed += count - kept;
      positions.resize(kept);
      if (mobile) mobile->resize(kept);
      upload();
      count = static_cast<std::uint32_t>(kept);
    }
    if (stats.mean_move_over_spacing < settings.tolerance) {
      stats.converged = true;
      break;
    }
  }
  project(count, settings.projection_steps);
  download(count);
  return stats;
}

}  // namespace ts::sampler
