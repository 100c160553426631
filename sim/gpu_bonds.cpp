// GpuStepper's bonds of breakable props (issue 48; the law sim/bond_model.h, its GLSL twin
// shaders/sim/bond.glsl). Each step, after the contact forces: bond_forces.comp advances every intact
// bond and breaks those past their strength (counted, and the lists rebuilt at the next step, all on
// the GPU), then bond_sums.comp adds each particle's bond loads to its wrench in ascending bond index,
// as the CPU reference does, so a run is the same bits every time. The bonds keep their world order;
// a re-sort only renames their spheres (resort_bonds.comp). At an output the energy they hold is
// summed per work group on the GPU (bond_energy.comp) and the partials in order on the host, as the
// bodies' energies are (reduce_metrics.comp).
#include <algorithm>
#include <bit>
#include <utility>

#include "shaders/sim/bindings.h"
#include "sim/gpu_stepper.h"

namespace ts::sim {
namespace {

void append(std::vector<double>& out, const Eigen::Vector3d& v, double w) { out.insert(out.end(), {v.x(), v.y(), v.z(), w}); }

// Each world particle's bonds, ascending (every bond, intact or not: the kernels test the flag):
// offsets over N + 1 entries, then per entry the bond index, the partner and the bond's rest overlap
// as float bits (TS_SIM_BOND_CSR).
std::vector<std::uint32_t> bond_csr(const BondSet& bonds, std::size_t particles) {
  std::vector<std::uint32_t> out(particles + 1, 0u);
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    ++out[bonds.a[k] + 1];
    ++out[bonds.b[k] + 1];
  }
  for (std::size_t i = 0; i < particles; ++i) out[i + 1] += out[i];
  out.resize(particles + 1 + TS_SIM_BOND_CSR_STRIDE * 2 * bonds.size());
  std::vector<std::uint32_t> next(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(particles));
  for (std::size_t k = 0; k < bonds.size(); ++k) {  // ascending k: each particle's entries ascend
    const std::uint32_t rest = std::bit_cast<std::uint32_t>(static_cast<float>(bonds.rest_overlap[k]));
    for (const auto& [self, other] : {std::pair{bonds.a[k], bonds.b[k]}, std::pair{bonds.b[k], bonds.a[k]}}) {
      std::uint32_t* entry = &out[particles + 1 + TS_SIM_BOND_CSR_STRIDE * next[self]++];
      entry[0] = static_cast<std::uint32_t>(k);
      entry[1] = other;
      entry[2] = rest;
    }
  }
  return out;
}

// Work groups of bond_energy.comp (256 bonds each), one partial each.
std::size_t energy_groups(std::uint32_t bonds) { return (std::size_t{bonds} + 255) / 256; }

}  // namespace

void GpuStepper::upload_bonds(const World& world) {
  const BondSet& bonds = world.bonds;
  bond_count_ = static_cast<std::uint32_t>(bonds.size());
  std::vector<std::uint32_t> pairs;
  std::vector<double> constants, state, energy_factors;
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    // GPU indices are the world's at upload; the re-sort that ends upload() renames them.
    pairs.insert(pairs.end(), {bonds.a[k], bonds.b[k], bonds.intact[k] ? 1u : 0u, 0u});
    const BondGeometry<double> g = bond_geometry(world.particles.radius[bonds.a[k]],
                                                 world.particles.radius[bonds.b[k]],
                                                 world.bond_materials[bonds.material[k]]);
    // sim::bond_energy's denominators, inverted once here in double (TS_SIM_BOND_ENERGY_FACTORS).
    energy_factors.insert(energy_factors.end(),
                          {1.0 / (2.0 * g.normal_stiffness * g.area), 1.0 / (2.0 * g.shear_stiffness * g.area),
                           1.0 / (2.0 * g.shear_stiffness * g.polar_inertia),
                           1.0 / (2.0 * g.normal_stiffness * g.bending_inertia)});
    constants.insert(constants.end(), {g.area, g.bending_inertia, g.polar_inertia, g.radius, g.normal_stiffness,
                                       g.shear_stiffness, bonds.tensile_strength[k], bonds.shear_strength[k]});
    const BondState<double>& s = bonds.state[k];
    append(state, s.shear_force, s.normal_force);
    append(state, s.bending_moment, s.twisting_moment);
  }
  // Placeholders keep the bindings valid in a world without bonds.
  if (pairs.empty()) pairs.assign(4, 0u);
  if (constants.empty()) constants.assign(8, 0.0);
  if (state.empty()) state.assign(8, 0.0);
  if (energy_factors.empty()) energy_factors.assign(4, 0.0);
  bond_pair_ = gpu::Buffer::from<std::uint32_t>(pairs);
  bond_csr_ = gpu::Buffer::from<std::uint32_t>(bond_csr(bonds, particle_count_));
  // Reals as the pipeline keeps them (GpuStepper::real_buffer lives in gpu_stepper.cpp).
  const auto reals = [&](const std::vector<double>& values) {
    return fp64() ? gpu::Buffer::from<double>(values)
                  : gpu::Buffer::from<float>(std::vector<float>(values.begin(), values.end()));
  };
  bond_constants_ = reals(constants);
  bond_state_ = reals(state);
  const std::size_t real_size = fp64() ? 8 : 4;
  bond_load_ = gpu::Buffer(std::max<std::size_t>(bond_count_, 1) * 16 * real_size);
  // Doubles in every pipeline, as the other energies' partials (reduce_metrics.comp).
  bond_energy_factors_ = gpu::Buffer::from<double>(energy_factors);
  bond_energy_partials_ = gpu::Buffer(std::max<std::size_t>(energy_groups(bond_count_), 1) * sizeof(double));
  bond_params_.values.sizes = {bond_count_, particle_count_, 0u, 0u};
  bond_params_.values.step.x = static_cast<float>(settings_.dt);
  bond_params64_.values.sizes = {bond_count_, particle_count_, 0u, 0u};
  bond_params64_.values.step.x = settings_.dt;
  bond_count_params_.values.count.x = bond_count_;
}

void GpuStepper::bond_passes() {
  bond_pair_.bind(TS_SIM_BOND_PAIR);
  bond_state_.bind(TS_SIM_BOND_STATE);
  bond_constants_.bind(TS_SIM_BOND_PARAMS);
  bond_load_.bind(TS_SIM_BOND_LOAD);
  list_state_.bind(TS_SIM_LIST_STATE);
  if (fp64()) {
    bond_params64_.bind(TS_SIM_PARAMS);
  } else {
    bond_params_.bind(TS_SIM_PARAMS);
  }
  queue_.dispatch_items(bond_forces_, bond_count_);
  bond_csr_.bind(TS_SIM_BOND_CSR);
  queue_.dispatch_items(bond_sums_, particle_count_);
}

void GpuStepper::rename_bonded_spheres() {
  bond_pair_.bind(TS_SIM_BOND_PAIR);
  new_of_old_.bind(TS_SIM_RESORT_DESTINATION);
  bond_count_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(resort_bonds_, bond_count_);
}

// Each intact bond's load^2 / (2 stiffness), summed per work group on the GPU and the partials in
// order here (bonds / 256 doubles read back instead of every bond's loads). At an output of advance(),
// download_bonds has just read those loads back for the world, so summing them on the host would
// cost no read there; the GPU sum serves statistics() without a download too (tests,
// bench/sim_accuracy.cpp).
double GpuStepper::bond_energy() {
  if (bond_count_ == 0) return 0.0;
  bond_pair_.bind(TS_SIM_BOND_PAIR);
  bond_state_.bind(TS_SIM_BOND_STATE);
  bond_energy_factors_.bind(TS_SIM_BOND_ENERGY_FACTORS);
  bond_energy_partials_.bind(TS_SIM_BOND_ENERGY_PARTIALS);
  bond_count_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(bond_energy_, bond_count_);
  bind_state();  // the pass took slots of the state
  double energy = 0.0;
  for (double partial : bond_energy_partials_.read<double>(energy_groups(bond_count_))) energy += partial;
  return energy;
}

void GpuStepper::download_bonds(World& world) const {
  if (bond_count_ == 0) return;
  const std::vector<std::uint32_t> pairs = bond_pair_.read<std::uint32_t>(4 * std::size_t{bond_count_});
  const std::vector<double> values = read_real(bond_state_, 8 * std::size_t{bond_count_});
  BondSet& bonds = world.bonds;
  for (std::size_t k = 0; k < bond_count_; ++k) {
    bonds.intact[k] = pairs[4 * k + 2] != 0u ? 1 : 0;
    const double* v = &values[8 * k];
    bonds.state[k].shear_force = {v[0], v[1], v[2]};
    bonds.state[k].normal_force = v[3];
    bonds.state[k].bending_moment = {v[4], v[5], v[6]};
    bonds.state[k].twisting_moment = v[7];
  }
}

}  // namespace ts::sim
