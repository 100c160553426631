// GpuStepper's contact candidate lists (sim/contact_lists.h): a skin around every particle, the hashed
// grid and the lists rebuilt only when some particle has moved more than half of it, decided on the
// GPU (list_decide.comp) and carried out by indirect dispatches, so a step still makes no host read.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "shaders/common/bindings.h"
#include "shaders/sim/bindings.h"
#include "sim/contact_lists.h"
#include "sim/gpu_stepper.h"

namespace ts::sim {
namespace {

// The list capacity K per particle. A candidate j of i lies wholly inside the ball of radius
// ri + 2 rj + skin <= 3 r_max + skin around i; spheres that do not overlap fill at most the densest
// packing's 74.05 % of it, so K = 0.7405 ((3 r_max + skin) / r_min)^3 holds every candidate of a
// packing of separate spheres (25 for equal spheres and a skin of a tenth of the diameter). Held to
// [16, 64]: the spheres of clumped grains overlap and wide size ranges give large bounds, and a
// particle with more candidates than K walks the grid instead (list_build.comp), missing none.
std::uint32_t list_capacity(double min_radius, double max_radius, double skin) {
  if (!(min_radius > 0.0)) return 16u;
  const double bound = 0.7405 * std::pow((3.0 * max_radius + skin) / min_radius, 3.0);
  return static_cast<std::uint32_t>(std::clamp(std::ceil(bound), 16.0, 64.0));
}

}  // namespace

void GpuStepper::allocate_lists(const World& world) {
  double min_radius = std::numeric_limits<double>::infinity(), max_radius = 0.0, extent = 0.0;
  for (double r : world.particles.radius) {
    min_radius = std::min(min_radius, r);
    max_radius = std::max(max_radius, r);
  }
  for (std::size_t k = 0; k < world.bodies.size(); ++k)
    extent = std::max(extent, world.bodies.position[k].cwiseAbs().maxCoeff() + world.bodies.bounding_radius[k]);
  skin_ = particle_count_ > 0 ? choose_skin(2.0 * max_radius, settings_.design_speed, settings_.dt, settings_.skin) : 0.0;
  list_cell_ = cell_size_ + skin_;
  list_capacity_ = list_capacity(min_radius, max_radius, skin_);
  const std::size_t particles = std::max<std::size_t>(particle_count_, 1);
  list_ = gpu::Buffer((list_capacity_ + std::size_t{1}) * particles * sizeof(std::uint32_t));
  build_position_ = gpu::Buffer(particles * 16);
  build_position_.fill_zero();
  list_state_ = gpu::Buffer(2 * sizeof(std::uint32_t));
  force_list_rebuild();
  // The list keeps a candidate up to the skin and a margin beyond contact: a hundredth of the skin,
  // and the float rounding of positions of the scene's extent (the double pipeline tests contacts on
  // unrounded positions, the lists and displacements use the float copy), twice over.
  const double margin = 0.01 * skin_ + 2.0 * 4.0 * std::numeric_limits<float>::epsilon() * 2.0 * extent;
  list_params_.values.sizes = {particle_count_, 0u, list_capacity_, 0u};
  list_params_.values.lengths = {static_cast<float>(list_cell_), static_cast<float>(skin_),
                                 static_cast<float>(skin_ + margin), 0.0f};
  // The rebuild's dispatch plan: its passes issued once as a dry run (nothing runs), recording the
  // group counts that list_decide.comp copies into the indirect arguments when it rebuilds.
  queue_.begin_indirect(nullptr);
  list_build_passes();
  list_plan_rows_ = queue_.end_indirect();
  const std::size_t rows = std::max<std::size_t>(list_plan_rows_.size(), 1);
  list_plan_ = gpu::Buffer(rows * 16);
  if (!list_plan_rows_.empty()) list_plan_.upload(list_plan_rows_.data(), list_plan_rows_.size() * 16);
  list_args_ = gpu::Buffer(rows * 16);
  list_args_.fill_zero();
  list_params_.values.sizes.w = static_cast<std::uint32_t>(list_plan_rows_.size());
}

void GpuStepper::force_list_rebuild() {
  const std::uint32_t state[2] = {0u, 1u};  // TS_SIM_LIST_MAX_DISPLACEMENT, TS_SIM_LIST_FORCED
  list_state_.upload(state, sizeof(state));
}

void GpuStepper::list_build_passes() {
  grid_.build(queue_, particle_position_, particle_count_, static_cast<float>(list_cell_));
  list_params_.values.sizes.y = grid_.table_size();
  bind_state();  // the grid's passes took low slots
  grid_.bind();
  list_.bind(TS_SIM_LIST);
  build_position_.bind(TS_SIM_BUILD_POSITION);
  bond_pair_.bind(TS_SIM_BOND_PAIR);  // intact bonded pairs are no candidates
  bond_csr_.bind(TS_SIM_BOND_CSR);
  list_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(list_build_, particle_count_);
}

void GpuStepper::update_lists() {
  list_state_.bind(TS_SIM_LIST_STATE);
  list_plan_.bind(TS_SIM_LIST_PLAN);
  list_args_.bind(TS_SIM_LIST_ARGS);
  counters_.bind(TS_SIM_COUNTERS);
  list_params_.bind(TS_SIM_PARAMS);
  // The indirect dispatches read the arguments as commands: hence the command barrier.
  queue_.dispatch_groups(list_decide_, 1, GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
  queue_.begin_indirect(&list_args_);
  list_build_passes();
  if (queue_.end_indirect() != list_plan_rows_) {
    throw std::logic_error("GpuStepper: the list rebuild's dispatches changed since their plan was recorded");
  }
}

std::string GpuStepper::list_report() {
  // Builds since the last statistics() are still in the counters: read them without clearing.
  const auto counters = counters_.read<std::uint32_t>(TS_SIM_COUNTER_LIST_OVERFLOWS + 1);
  const std::uint64_t builds = list_builds_ + counters[TS_SIM_COUNTER_LIST_BUILDS];
  const std::uint64_t overflows = list_overflows_ + counters[TS_SIM_COUNTER_LIST_OVERFLOWS];
  const double diameter = cell_size_;
  return fmt::format(
      "contact lists: skin {:.3g} m ({:.3g} x the largest diameter), grid cell {:.3g} m; {} builds in {} steps "
      "({:.1f} steps a build); capacity K = {} candidates a particle, {} overflows (particle-builds that walked "
      "the grid)\n",
      skin_, diameter > 0 ? skin_ / diameter : 0.0, list_cell_, builds, steps_run_,
      builds > 0 ? static_cast<double>(steps_run_) / static_cast<double>(builds) : 0.0, list_capacity_, overflows);
}

}  // namespace ts::sim
