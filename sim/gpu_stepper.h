#pragma once
// The GPU pipeline of the DEM, stage for stage the same as CpuStepper (sim/cpu_stepper.h) on the same
// World: poses -> particle positions and velocities -> (when the contact candidate lists are stale,
// decided on the GPU) hashed grid (counting sort) and lists -> contact forces gathered per particle
// over its list (no float atomics) -> per-body sums and integration. Steps run with no CPU round
// trip; statistics and state are read back only when asked. Bonded spheres (breakable props) take
// their bonds' loads after the contacts (sim/gpu_bonds.cpp). What only the CPU reference
// computes (contact dumps, the spring energy of a loaded state) comes from sim/cpu_contacts.h.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/hash_grid.h"
#include "gpu/host_sync.h"
#include "gpu/params.h"
#include "sim/stepper.h"
#include "sim/world.h"

namespace ts::sim {

// Float: float state and arithmetic. Double: double state and integration, contact arithmetic in float
// on double-differenced positions and velocities (mixed precision; `--precision double`). FullDouble:
// the contact kernel in double too, kept only to measure Double against (tests and bench/sim_accuracy).
enum class Precision { Float, Double, FullDouble };

class GpuStepper : public Stepper {
 public:
  // Compiles the kernels; load() gives the state.
  GpuStepper(gpu::Context& context, const StepSettings& settings, Precision precision = Precision::Float,
             bool timings = false);
  // The same, loaded with `world`.
  GpuStepper(gpu::Context& context, const World& world, const StepSettings& settings,
             Precision precision = Precision::Float, bool timings = false);

  // Replaces the whole GPU state with `world` (bodies, particles, walls, materials).
  void load(const World& world) override { upload(world); }
  // step(), statistics() and download() in one.
  StepStats advance(World& world, std::int64_t steps) override;
  // Recomputed by the CPU reference on `world` (sim/cpu_contacts.h).
  std::vector<ContactRecord> contacts(const World& world) override;
  // Per-kernel GPU times, then the host-GPU round trips of the steps, of the outputs and in all.
  std::string timing_report() override;
  const StepSettings& settings() const override { return settings_; }
  std::string engine() const override {
    return precision_ == Precision::Float ? "gpu float" : precision_ == Precision::Double ? "gpu double" : "gpu full double";
  }
  // The persistent buffers in GPU memory order, the re-sort counter, the time and the energy check's
  // reference; the device's renderer goes along (another device continues, with a warning, not bitwise).
  std::string save_state() const override;
  void restore_state(const World& world, std::string_view state) override;

  void upload(const World& world);
  // Advances `steps` time steps of settings.dt.
  void step(int steps = 1);
  // Statistics of the last step (energies, contacts, overlap; clamp, overflow and penetration counts
  // since the last call). Throws ts::Error(ExitCode::Unstable) on a non-finite state, WallPenetration
  // on a penetration, and on energy growth without work.
  StepStats statistics();
  // Bodies' positions, orientations and velocities back into `world` (its time advanced too), and
  // with the spring tangential model the contact springs.
  void download(World& world) const;
  // Per-particle contact force [N] of the last step, in world particle order (for tests against the
  // CPU reference).
  std::vector<Eigen::Vector3d> particle_forces() const;
  double time() const { return time_; }
  std::size_t gpu_bytes() const;
  // The contact candidate lists (sim/contact_lists.h): skin [m], grid cell [m], capacity K per
  // particle, and the builds and overflows (particles that had more than K candidates, summed over
  // builds) counted on the GPU and read by statistics().
  struct ListStats {
    double skin = 0.0, cell = 0.0;
    std::uint32_t capacity = 0;
    std::uint64_t builds = 0, overflows = 0;
  };
  ListStats list_stats() const { return {skin_, list_cell_, list_capacity_, list_builds_, list_overflows_}; }
  // The world index of each body in GPU memory order (bodies are re-sorted at load and then every
  // StepSettings::resort_every steps).
  std::vector<std::uint32_t> body_order() const { return original_ids(original_body_, body_count_); }
  // Host-GPU round trips by phase (gpu/host_sync.h): inside step() (none, by design), inside
  // advance()'s read-backs after the steps, and all this thread's since this stepper was made
  // (with the frames `sim` renders in the same context).
  std::vector<gpu::HostSyncPhase> round_trips() const;

 private:
  // Double-precision state (Double and FullDouble).
  bool fp64() const { return precision_ != Precision::Float; }
  template <typename T>
  gpu::Buffer real_buffer(const std::vector<T>& values) const;
  std::vector<double> read_real(const gpu::Buffer& buffer, std::size_t count) const;
  void bind_state() const;
  // The steps of upload().
  void upload_bodies(const World& world);
  void upload_particles(const World& world);
  void upload_springs(const World& world);
  void allocate_statistics();
  void upload_materials_and_walls(const World& world);
  // Fills the kernels' parameters that change only with the world (after rebuild).
  void set_params();
  // Bind the contact and integration parameters with what changes every step.
  void bind_contact_params(std::uint32_t table_size);
  void bind_integrate_params(double time_after);
  void download_springs(World& world) const;
  // Bonds of breakable props (sim/gpu_bonds.cpp): their buffers from `world` (placeholders without
  // bonds, so list_build always has its bindings); each step's two passes (the loads and breaks, then
  // the per-particle sums into the wrench); their spheres renamed after a re-sort; the energy they
  // hold (J, per work group on the GPU, the partials added in order); their state back into `world`.
  void upload_bonds(const World& world);
  void bond_passes();
  void rename_bonded_spheres();
  double bond_energy();
  void download_bonds(World& world) const;
  std::size_t counter_count() const;  // uints of counters_
  Penetration penetration(const std::vector<std::uint32_t>& counters) const;
  void allocate_resort(std::uint32_t body_count, std::uint32_t particle_count);
  // Re-sorts bodies (and their particles, springs renamed) by the cell of their centre; forces a
  // list rebuild.
  void resort();
  // Contact candidate lists (sim/gpu_lists.cpp): sizes and the rebuild's dispatch plan, from the
  // radii of `world`; the rebuild passes (the grid and the list build); each step's decision and the
  // passes it enables; a rebuild at the next step whatever the displacement.
  void allocate_lists(const World& world);
  void list_build_passes();
  void update_lists();
  void force_list_rebuild();
  std::string list_report();
  // buffer = its rows reordered: row r takes old row index[r]; rows of `width` 16-byte words.
  void gather(gpu::Buffer& buffer, const gpu::Buffer& index, std::uint32_t rows, std::uint32_t width);
  // World index of each GPU body and particle (identity until the first re-sort).
  std::vector<std::uint32_t> original_ids(const gpu::Buffer& ids, std::uint32_t count) const;
  // The buffers a step carries over to the next (everything else is recomputed each step), as
  // pointers to const when `self` is.
  template <typename Self>
  static auto persistent_buffers(Self& self) {
    return std::array{&self.body_position_, &self.body_orientation_,     &self.body_velocity_,
                      &self.body_omega_,    &self.body_inverse_inertia_, &self.body_range_,
                      &self.body_momentum_, &self.particle_info_,        &self.particle_local_,
                      &self.springs_,       &self.original_body_,        &self.original_particle_};
  }

  gpu::Context& context_;
  StepSettings settings_;
  Precision precision_;
  gpu::ShaderLibrary library_;
  gpu::Queue queue_;
  gpu::Program update_, contacts_, integrate_, metrics_, particle_stats_;
  // Each kernel's parameters (shaders/common/params.h), bound before each of its dispatches. The
  // contact and integration kernels read the *64 forms in the double-precision pipeline.
  gpu::ParamBlock<gpu::params::ItemCount> update_params_, particle_stats_params_;
  gpu::ParamBlock<gpu::params::SimContactParams> contact_params_;
  gpu::ParamBlock<gpu::params::SimContactParams64> contact_params64_;
  gpu::ParamBlock<gpu::params::SimIntegrateParams> integrate_params_;
  gpu::ParamBlock<gpu::params::SimIntegrateParams64> integrate_params64_;
  gpu::ParamBlock<gpu::params::SimMetricsParams> metrics_params_;
  gpu::HashGrid grid_;
  gpu::Buffer particle_position_, particle_position_exact_, particle_velocity_, particle_info_, particle_local_;
  gpu::Buffer body_position_, body_orientation_, body_velocity_, body_omega_, body_inverse_inertia_, body_range_;
  gpu::Buffer body_momentum_, particle_wrench_, springs_, keyframes_, pairs_, planes_, cylinders_, particle_stats_buffer_;
  gpu::Buffer counters_, metric_partials_, stat_partials_;
  // Re-sorting (see StepSettings::resort_every).
  gpu::Program resort_keys_, resort_ranges_, resort_particles_, resort_fixup_, gather_rows_;
  gpu::ParamBlock<gpu::params::GridParams> resort_keys_params_;
  gpu::ParamBlock<gpu::params::ItemCount> resort_bodies_params_;  // resort_ranges_ and resort_particles_
  gpu::ParamBlock<gpu::params::SimFixupParams> resort_fixup_params_;
  gpu::ParamBlock<gpu::params::SimGatherParams> gather_rows_params_;
  gpu::BucketSort bucket_sort_;  // the body order by Morton key
  gpu::PrefixScan resort_scan_;  // the new particle ranges
  gpu::Buffer sort_key_, sort_slot_, bucket_count_, bucket_start_, order_, new_first_, new_range_;
  gpu::Buffer source_particle_, new_of_old_, owner_, original_body_, original_particle_;
  std::uint32_t bucket_table_ = 0;
  // Contact candidate lists (TS_SIM_LIST*).
  gpu::Program list_decide_, list_build_;
  gpu::ParamBlock<gpu::params::SimListParams> list_params_;
  gpu::Buffer list_, build_position_, list_state_, list_plan_, list_args_;
  std::vector<std::array<std::uint32_t, 4>> list_plan_rows_;  // what list_plan_ holds
  double skin_ = 0.0, list_cell_ = 0.0;                       // m
  std::uint32_t list_capacity_ = 0;
  std::uint64_t list_builds_ = 0, list_overflows_ = 0;
  // Bonds (TS_SIM_BOND_*), their kernels (the energy's per work group: sim/bond_energy.comp) and
  // parameters, and buffers.
  gpu::Program bond_forces_, bond_sums_, resort_bonds_, bond_energy_;
  gpu::ParamBlock<gpu::params::SimBondParams> bond_params_;
  gpu::ParamBlock<gpu::params::SimBondParams64> bond_params64_;
  gpu::ParamBlock<gpu::params::ItemCount> bond_count_params_;  // x: bonds (resort_bonds_, bond_energy_*)
  gpu::Buffer bond_pair_, bond_csr_, bond_state_, bond_constants_, bond_load_;
  gpu::Buffer bond_energy_factors_, bond_energy_partials_;
  std::uint32_t bond_count_ = 0;
  std::int64_t steps_since_resort_ = 0;
  std::uint32_t particle_count_ = 0, body_count_ = 0, plane_count_ = 0, cylinder_count_ = 0, material_count_ = 0;
  double cell_size_ = 0.0;  // m: the largest particle diameter, as the CPU reference
  double time_ = 0.0;
  double energy_reference_ = 0.0, energy_scale_ = 0.0;  // J, blow-up check as CpuStepper
  bool any_kinematic_ = false;                          // kinematic bodies do work: no energy check
  bool loaded_ = false;
  // For round_trips(): what the steps and the outputs cost, and the counts when this was made.
  gpu::HostSyncCounts step_syncs_, output_syncs_, syncs_at_start_;
  std::int64_t steps_run_ = 0, outputs_ = 0;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
};

}  // namespace ts::sim
