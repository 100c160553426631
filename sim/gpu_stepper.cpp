#include "sim/gpu_stepper.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "gpu/layouts.h"
#include "shaders/common/bindings.h"
#include "shaders/sim/bindings.h"
#include "sim/cpu_bonds.h"
#include "sim/cpu_contacts.h"
#include "sim/state_bytes.h"

namespace ts::sim {
namespace {

using gpu::layout::SimCylinder;
using gpu::layout::SimPair;
using gpu::layout::SimPlane;
using gpu::layout::SimSpringSlots;
using gpu::layout::SimSpringSlots64;
static_assert(ContactSprings::kSlots == TS_SIM_SPRING_SLOTS, "CPU and GPU keep the same number of springs");

std::vector<std::string> precision_defines(Precision precision) {
  return precision != Precision::Float ? std::vector<std::string>{"TS_FP64 1"} : std::vector<std::string>{};
}

// The bond kernels' arithmetic follows the contact kernel's (sim/precision.glsl, creal).
std::vector<std::string> bond_defines(Precision precision) {
  std::vector<std::string> defines = precision_defines(precision);
  if (precision == Precision::FullDouble) defines.emplace_back("TS_CONTACT_FP64 1");
  return defines;
}

// The contact kernel's specialisation for these settings and a world with or without walls
// (shaders/sim/contact_forces.comp, TS_CONTACT_*): switches the whole scene shares are compiled in, so
// what is off (the spring history above all) costs the kernel no registers.
std::vector<std::string> contact_defines(Precision precision, const StepSettings& s, bool walls, bool bonds) {
  std::vector<std::string> defines = precision_defines(precision);
  if (precision == Precision::FullDouble) defines.emplace_back("TS_CONTACT_FP64 1");
  defines.push_back(fmt::format("TS_CONTACT_SPRINGS {}", s.tangential == TangentialModel::Spring ? 1 : 0));
  defines.push_back(fmt::format("TS_CONTACT_DAMPING {}", s.normal_damping == NormalDamping::Tsuji ? 0 : 1));
  defines.push_back(fmt::format("TS_CONTACT_WALLS {}", walls ? 1 : 0));
  defines.push_back(fmt::format("TS_CONTACT_PENETRATION {}", s.check_penetration ? 1 : 0));
  defines.push_back(fmt::format("TS_CONTACT_BONDS {}", bonds ? 1 : 0));
  return defines;
}

void append(std::vector<double>& out, const Eigen::Vector3d& v, double w) {
  out.insert(out.end(), {v.x(), v.y(), v.z(), w});
}

struct EnergyCheck {
  double reference = 0.0, scale = 0.0;
};

// Energy (J) in the contact springs of `world` as uploaded, found once by the CPU reference's contact
// stage: initial overlaps that relax turn it into kinetic energy, which is no blow-up.
double spring_energy(const World& world, const StepSettings& settings) {
  if (world.particles.size() == 0) return 0.0;
  return CpuContacts(settings).elastic_energy(world);
}

EnergyCheck energy_check(const World& world, const StepSettings& settings) {
  // The same reference and scale as CpuStepper: total energy now plus the springs', and kinetic and
  // spring energy plus the potential energy of lifting every dynamic body by one particle diameter
  // and a 1 cm/s stir (a finite scale without gravity).
  const Energy e = energy(world);
  double mass = 0.0, diameter = 0.0;
  for (std::size_t k = 0; k < world.bodies.size(); ++k)
    if (world.bodies.motion[k] == MotionType::Dynamic) mass += 1.0 / world.bodies.inverse_mass[k];
  for (double r : world.particles.radius) diameter = std::max(diameter, 2 * r);
  const double springs = settings.check_energy ? spring_energy(world, settings) : 0.0;
  const double bonds = bond_energy(world);
  return {e.total() + springs + bonds,
          e.translational + e.rotational + springs + bonds + mass * (world.gravity.norm() * diameter + 1e-4)};
}

}  // namespace

GpuStepper::GpuStepper(gpu::Context& context, const World& world, const StepSettings& settings, Precision precision,
                       bool timings)
    : GpuStepper(context, settings, precision, timings) {
  upload(world);
}

GpuStepper::GpuStepper(gpu::Context& context, const StepSettings& settings, Precision precision, bool timings)
    : context_(context),
      settings_(settings),
      precision_(precision),
      queue_(timings, context.debug()),
      update_(gpu::Program::compute(library_, "sim/update_particles.comp", precision_defines(precision))),
      integrate_(gpu::Program::compute(library_, "sim/integrate_bodies.comp", precision_defines(precision))),
      metrics_(gpu::Program::compute(library_, "sim/reduce_metrics.comp", precision_defines(precision))),
      particle_stats_(gpu::Program::compute(library_, "sim/reduce_particle_stats.comp")),
      grid_(library_),
      resort_keys_(gpu::Program::compute(library_, "sim/resort_keys.comp", precision_defines(precision))),
      resort_ranges_(gpu::Program::compute(library_, "sim/resort_ranges.comp")),
      resort_particles_(gpu::Program::compute(library_, "sim/resort_particles.comp")),
      resort_fixup_(gpu::Program::compute(library_, "sim/resort_fixup.comp", precision_defines(precision))),
      gather_rows_(gpu::Program::compute(library_, "sim/gather_rows.comp")),
      bucket_sort_(library_),
      resort_scan_(library_),
      list_decide_(gpu::Program::compute(library_, "sim/list_decide.comp")),
      list_build_(gpu::Program::compute(library_, "sim/list_build.comp", precision_defines(precision))),
      bond_forces_(gpu::Program::compute(library_, "sim/bond_forces.comp", bond_defines(precision))),
      bond_sums_(gpu::Program::compute(library_, "sim/bond_sums.comp", bond_defines(precision))),
      resort_bonds_(gpu::Program::compute(library_, "sim/resort_bonds.comp")),
      bond_energy_(gpu::Program::compute(library_, "sim/bond_energy.comp", precision_defines(precision))),
      syncs_at_start_(gpu::host_sync_counts()) {}

template <typename T>
gpu::Buffer GpuStepper::real_buffer(const std::vector<T>& values) const {
  if (fp64()) return gpu::Buffer::from<double>(std::vector<double>(values.begin(), values.end()));
  const std::vector<float> narrow(values.begin(), values.end());
  return gpu::Buffer::from<float>(narrow);
}

std::vector<double> GpuStepper::read_real(const gpu::Buffer& buffer, std::size_t count) const {
  if (fp64()) return buffer.read<double>(count);
  const auto values = buffer.read<float>(count);
  return {values.begin(), values.end()};
}

namespace {

// Body state as the kernels read it: one real4 row per body and quantity (three for the inverse
// inertia), and keyframed tracks appended to one key buffer.
struct PackedBodies {
  std::vector<double> position, orientation, velocity, omega, inverse_inertia, momentum, keys;
  std::vector<std::uint32_t> range;  // uvec4 per body: first particle, count, first key, key count
};

double motion_code(MotionType motion) {
  return motion == MotionType::Dynamic     ? TS_MOTION_DYNAMIC
         : motion == MotionType::Kinematic ? TS_MOTION_KINEMATIC
                                           : TS_MOTION_STATIC;
}

void pack_body(const Bodies& b, std::size_t k, PackedBodies& out) {
  const bool dynamic = b.motion[k] == MotionType::Dynamic;
  append(out.position, b.position[k], dynamic ? b.inverse_mass[k] : 0.0);
  const Eigen::Quaterniond& q = b.orientation[k];
  out.orientation.insert(out.orientation.end(), {q.x(), q.y(), q.z(), q.w()});
  append(out.velocity, b.linear_velocity[k], motion_code(b.motion[k]));
  append(out.omega, b.angular_velocity[k], 0.0);
  const Eigen::Matrix3d inv = dynamic ? b.inverse_inertia[k] : Eigen::Matrix3d::Zero();
  for (int row = 0; row < 3; ++row) append(out.inverse_inertia, inv.row(row).transpose(), row == 0 ? b.bounding_radius[k] : 0.0);
  // The GPU integrates the angular momentum L = I_world omega (omega = R I0^-1 R^T L).
  Eigen::Vector3d l = Eigen::Vector3d::Zero();
  if (dynamic) {
    const Eigen::Matrix3d r = q.toRotationMatrix();
    l = (r * b.inverse_inertia[k] * r.transpose()).inverse() * b.angular_velocity[k];
  }
  append(out.momentum, l, 0.0);
  out.range.insert(out.range.end(), {b.first_particle[k], b.particle_count[k], 0u, 0u});
}

PackedBodies pack_bodies(const World& world) {
  PackedBodies out;
  for (std::size_t k = 0; k < world.bodies.size(); ++k) pack_body(world.bodies, k, out);
  // Keyframed kinematic bodies: their keys, and where they start in body_range's z and w.
  for (const KinematicTrack& track : world.tracks) {
    out.range[4 * track.body + 2] = static_cast<std::uint32_t>(out.keys.size() / 8);
    out.range[4 * track.body + 3] = static_cast<std::uint32_t>(track.keys.size());
    for (const Keyframe& key : track.keys) {
      append(out.keys, key.position, key.time);
      out.keys.insert(out.keys.end(), {key.orientation.x(), key.orientation.y(), key.orientation.z(), key.orientation.w()});
    }
  }
  if (out.keys.empty()) out.keys.assign(8, 0.0);  // a placeholder keeps the binding valid
  return out;
}

std::vector<SimPair> pack_pairs(const std::vector<Material>& materials, const StepSettings& settings) {
  std::vector<SimPair> pairs;
  for (const Material& a : materials) {
    for (const Material& c : materials) {
      const PairCoefficients k = make_pair_coefficients(a, c, settings.normal_damping, settings.thesis_reference_speed);
      SimPair pair{};
      pair.coefficients = {static_cast<float>(k.effective_modulus), static_cast<float>(k.friction),
                           static_cast<float>(k.tangential_damping), static_cast<float>(k.damping_strength)};
      pair.extra = {static_cast<float>(k.thesis_reference_speed), static_cast<float>(k.effective_shear_modulus), 0.0f,
                    0.0f};
      pairs.push_back(pair);
    }
  }
  return pairs;
}

std::vector<SimPlane> pack_planes(const std::vector<PlaneWall>& walls) {
  std::vector<SimPlane> planes;
  for (const PlaneWall& w : walls) {
    SimPlane plane{};
    plane.normal_offset = {static_cast<float>(w.normal.x()), static_cast<float>(w.normal.y()),
                           static_cast<float>(w.normal.z()), static_cast<float>(w.normal.dot(w.point))};
    plane.extent = {0.0f, 0.0f, 0.0f, 0.0f};
    plane.material = {w.material, 0u, 0u, 0u};
    planes.push_back(plane);
  }
  return planes;
}

std::vector<SimCylinder> pack_cylinders(const std::vector<CylinderWall>& walls) {
  std::vector<SimCylinder> cylinders;
  for (const CylinderWall& w : walls) {
    SimCylinder c{};
    c.axis_radius = {static_cast<float>(w.axis.x()), static_cast<float>(w.axis.y()), 0.0f, static_cast<float>(w.radius)};
    c.range = {static_cast<float>(std::max(w.z_min, -1e30)), static_cast<float>(std::min(w.z_max, 1e30)), 0.0f, 0.0f};
    c.material = {w.material, 0u, 0u, 0u};
    cylinders.push_back(c);
  }
  return cylinders;
}

}  // namespace

void GpuStepper::upload(const World& world) {
  loaded_ = true;
  body_count_ = static_cast<std::uint32_t>(world.bodies.size());
  particle_count_ = static_cast<std::uint32_t>(world.particles.size());
  time_ = world.time;
  gravity_ = world.gravity;
  const EnergyCheck check = energy_check(world, settings_);
  energy_reference_ = check.reference;
  energy_scale_ = check.scale;
  any_kinematic_ = std::find(world.bodies.motion.begin(), world.bodies.motion.end(), MotionType::Kinematic) !=
                   world.bodies.motion.end();
  upload_bodies(world);
  upload_particles(world);
  upload_springs(world);
  upload_bonds(world);  // before allocate_lists: the list build binds the bonds
  allocate_resort(body_count_, particle_count_);
  upload_materials_and_walls(world);
  // Compiled for this world (walls or none, bonds or none); the context's program cache links each variant once.
  contacts_ = gpu::Program::compute(library_, "sim/contact_forces.comp",
                                    contact_defines(precision_, settings_, plane_count_ + cylinder_count_ > 0,
                                                    bond_count_ > 0));
  allocate_statistics();
  allocate_lists(world);  // before set_params: the contact kernel's grid cell and capacity
  set_params();
  // Bodies in cell order from the first step (the gathers' locality), not only after resort_every.
  if (settings_.resort_every > 0) resort();
}

void GpuStepper::upload_bodies(const World& world) {
  const PackedBodies packed = pack_bodies(world);
  body_position_ = real_buffer(packed.position);
  body_orientation_ = real_buffer(packed.orientation);
  body_velocity_ = real_buffer(packed.velocity);
  body_omega_ = real_buffer(packed.omega);
  body_inverse_inertia_ = real_buffer(packed.inverse_inertia);
  body_momentum_ = real_buffer(packed.momentum);
  body_range_ = gpu::Buffer::from<std::uint32_t>(packed.range);
  keyframes_ = real_buffer(packed.keys);
}

void GpuStepper::upload_particles(const World& world) {
  const Particles& p = world.particles;
  std::vector<double> local;
  std::vector<std::uint32_t> info;
  double max_radius = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    append(local, p.offset[i], p.radius[i]);
    info.insert(info.end(), {p.body[i], p.material[i], static_cast<std::uint32_t>(i), 0u});
    max_radius = std::max(max_radius, p.radius[i]);
  }
  cell_size_ = particle_count_ > 0 ? 2.0 * max_radius : 1.0;
  const std::size_t real_size = fp64() ? 8 : 4;
  particle_local_ = real_buffer(local);
  particle_info_ = gpu::Buffer::from<std::uint32_t>(info);
  const std::size_t particles = particle_count_;  // size_t products: no 32-bit overflow
  particle_position_ = gpu::Buffer(particles * 16);
  particle_position_exact_ = gpu::Buffer(fp64() ? particles * 32 : 16);
  particle_velocity_ = gpu::Buffer(particles * 4 * real_size);
  particle_wrench_ = gpu::Buffer(particles * 8 * real_size);
}

void GpuStepper::allocate_statistics() {
  particle_stats_buffer_ = gpu::Buffer(std::size_t{particle_count_} * 16);
  counters_ = gpu::Buffer(counter_count() * sizeof(std::uint32_t));
  counters_.fill_zero();
  metric_partials_ = gpu::Buffer((std::size_t{(body_count_ + 255) / 256} + 1) * 32);
  stat_partials_ = gpu::Buffer((std::size_t{(particle_count_ + 255) / 256} + 1) * 16);
}

std::size_t GpuStepper::counter_count() const {
  return TS_SIM_COUNTER_WALL_SLOTS + std::size_t{plane_count_} + cylinder_count_;
}

// The wall slots of the counters: the lowest world particle id found behind any wall, and the first
// wall (planes, then cylinders) that found it.
Penetration GpuStepper::penetration(const std::vector<std::uint32_t>& counters) const {
  Penetration p;
  p.count = counters[TS_SIM_COUNTER_PENETRATIONS];
  if (p.count == 0) return p;
  std::size_t first = TS_SIM_COUNTER_WALL_SLOTS;
  for (std::size_t s = TS_SIM_COUNTER_WALL_SLOTS; s < counters.size(); ++s)
    if (counters[s] > counters[first]) first = s;
  p.particle = ~counters[first];
  p.wall = static_cast<std::int64_t>(first - TS_SIM_COUNTER_WALL_SLOTS);
  return p;
}

void GpuStepper::upload_materials_and_walls(const World& world) {
  material_count_ = static_cast<std::uint32_t>(world.materials.size());
  pairs_ = gpu::Buffer::from<SimPair>(pack_pairs(world.materials, settings_));
  const std::vector<SimPlane> planes = pack_planes(world.walls.planes);
  const std::vector<SimCylinder> cylinders = pack_cylinders(world.walls.cylinders);
  plane_count_ = static_cast<std::uint32_t>(planes.size());
  cylinder_count_ = static_cast<std::uint32_t>(cylinders.size());
  planes_ = gpu::Buffer::from<SimPlane>(planes);
  cylinders_ = gpu::Buffer::from<SimCylinder>(cylinders);
}

namespace {

// The contact kernel's parameters but the hash table size (set each step); Params: SimContactParams,
// or SimContactParams64, whose step length is a double.
template <typename Params>
void fill_contact_params(Params& p, const StepSettings& s, std::uint32_t particles, std::uint32_t planes,
                         std::uint32_t cylinders, std::uint32_t materials, double cell_size,
                         std::uint32_t capacity) {
  p.sizes = {particles, p.sizes.y, planes, cylinders};
  p.materials = {materials, 0u, 0u, 0u};
  p.limits = {static_cast<float>(cell_size),
              static_cast<float>(s.max_overlap_ratio > 0 ? s.max_overlap_ratio : 1e30), 0.0f, 0.0f};
  p.step.x = static_cast<decltype(p.step.x)>(s.dt);
  p.lists = {capacity, 0u, 0u, 0u};
}

// The integration kernel's parameters but the step's end time (set each step); Params:
// SimIntegrateParams or SimIntegrateParams64.
template <typename Params>
void fill_integrate_params(Params& p, const StepSettings& s, std::uint32_t bodies, const Eigen::Vector3d& gravity,
                           double max_speed) {
  using Real = decltype(p.time.x);
  p.sizes = {bodies, 0u, 0u, 0u};
  p.models = {s.integrator == Integrator::SemiImplicitEuler ? 1 : 0, 0, 0, 0};
  p.limits = {static_cast<float>(std::min(max_speed, 1e30)), static_cast<float>(s.angular_damping_rate),
              static_cast<float>(s.angular_damping_speed), 0.0f};
  p.gravity_dt = {static_cast<Real>(gravity.x()), static_cast<Real>(gravity.y()), static_cast<Real>(gravity.z()),
                  static_cast<Real>(s.dt)};
}

}  // namespace

void GpuStepper::set_params() {
  const double max_speed = settings_.cfl > 0 ? settings_.cfl * cell_size_ / settings_.dt : 1e30;
  update_params_.values.count.x = particle_count_;
  fill_contact_params(contact_params_.values, settings_, particle_count_, plane_count_, cylinder_count_,
                      material_count_, list_cell_, list_capacity_);
  fill_contact_params(contact_params64_.values, settings_, particle_count_, plane_count_, cylinder_count_,
                      material_count_, list_cell_, list_capacity_);
  fill_integrate_params(integrate_params_.values, settings_, body_count_, gravity_, max_speed);
  fill_integrate_params(integrate_params64_.values, settings_, body_count_, gravity_, max_speed);
  metrics_params_.values.sizes.x = body_count_;
  metrics_params_.values.gravity = {static_cast<float>(gravity_.x()), static_cast<float>(gravity_.y()),
                                    static_cast<float>(gravity_.z()), 0.0f};
  particle_stats_params_.values.count.x = particle_count_;
}

void GpuStepper::bind_contact_params(std::uint32_t table_size) {
  if (fp64()) {
    contact_params64_.values.sizes.y = table_size;
    contact_params64_.bind(TS_SIM_PARAMS);
  } else {
    contact_params_.values.sizes.y = table_size;
    contact_params_.bind(TS_SIM_PARAMS);
  }
}

void GpuStepper::bind_integrate_params(double time_after) {
  if (fp64()) {
    integrate_params64_.values.time.x = time_after;
    integrate_params64_.bind(TS_SIM_PARAMS);
  } else {
    integrate_params_.values.time.x = static_cast<float>(time_after);
    integrate_params_.bind(TS_SIM_PARAMS);
  }
}

void GpuStepper::bind_state() const {
  particle_position_.bind(TS_SIM_PARTICLE_POSITION);
  particle_velocity_.bind(TS_SIM_PARTICLE_VELOCITY);
  particle_info_.bind(TS_SIM_PARTICLE_INFO);
  particle_local_.bind(TS_SIM_PARTICLE_LOCAL);
  body_position_.bind(TS_SIM_BODY_POSITION);
  body_orientation_.bind(TS_SIM_BODY_ORIENTATION);
  body_velocity_.bind(TS_SIM_BODY_VELOCITY);
  body_omega_.bind(TS_SIM_BODY_OMEGA);
  body_inverse_inertia_.bind(TS_SIM_BODY_INV_INERTIA);
  body_range_.bind(TS_SIM_BODY_RANGE);
  particle_wrench_.bind(TS_SIM_PARTICLE_WRENCH);
  springs_.bind(TS_SIM_SPRINGS);
  keyframes_.bind(TS_SIM_KEYFRAMES);
  pairs_.bind(TS_SIM_PAIRS);
  planes_.bind(TS_SIM_PLANES);
  cylinders_.bind(TS_SIM_CYLINDERS);
  particle_stats_buffer_.bind(TS_SIM_PARTICLE_STATS);
  counters_.bind(TS_SIM_COUNTERS);
  body_momentum_.bind(TS_SIM_BODY_MOMENTUM);
  particle_position_exact_.bind(TS_SIM_PARTICLE_POSITION_EXACT);
}

void GpuStepper::step(int steps) {
  const gpu::HostSyncScope counted(step_syncs_);
  steps_run_ += steps;
  if (particle_count_ == 0) {
    time_ += steps * settings_.dt;
    return;
  }
  for (int s = 0; s < steps; ++s) {
    // The re-sort stays on a host schedule rather than following the GPU's list rebuilds: its
    // gathers swap freshly allocated buffers in on the host, so it cannot be an indirect dispatch as
    // it stands; every 100 steps it costs a few bytes a grain-step (docs/architecture.md).
    if (settings_.resort_every > 0 && steps_since_resort_ >= settings_.resort_every) resort();
    ++steps_since_resort_;
    bind_state();
    build_position_.bind(TS_SIM_BUILD_POSITION);
    list_state_.bind(TS_SIM_LIST_STATE);
    update_params_.bind(TS_SIM_PARAMS);
    queue_.dispatch_items(update_, particle_count_);
    update_lists();
    bind_state();
    grid_.bind();
    list_.bind(TS_SIM_LIST);
    bond_csr_.bind(TS_SIM_BOND_CSR);  // read with TS_CONTACT_BONDS
    bind_contact_params(grid_.table_size());
    queue_.dispatch_items(contacts_, particle_count_);
    if (bond_count_ > 0) {
      bond_passes();
      bind_state();  // the bond passes took slots of the state
    }
    bind_integrate_params(time_ + settings_.dt);
    queue_.dispatch_items(integrate_, body_count_);
    time_ += settings_.dt;
  }
}

StepStats GpuStepper::statistics() {
  StepStats stats;
  bind_state();
  metric_partials_.bind(TS_SIM_METRIC_PARTIALS);
  stat_partials_.bind(TS_SIM_STAT_PARTIALS);
  metrics_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(metrics_, body_count_);
  particle_stats_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(particle_stats_, particle_count_);
  const auto energies = metric_partials_.read<double>(4 * ((body_count_ + 255) / 256));
  double bad = 0.0;
  for (std::size_t g = 0; g < energies.size(); g += 4) {
    stats.energy.translational += energies[g];
    stats.energy.rotational += energies[g + 1];
    stats.energy.potential += energies[g + 2];
    bad += energies[g + 3];
  }
  const auto contact = stat_partials_.read<float>(4 * ((particle_count_ + 255) / 256));
  for (std::size_t g = 0; g < contact.size(); g += 4) {
    stats.contacts += static_cast<std::size_t>(contact[g]);
    stats.wall_contacts += static_cast<std::size_t>(contact[g + 1]);
    stats.max_overlap_ratio = std::max(stats.max_overlap_ratio, static_cast<double>(contact[g + 2]));
    stats.overlap_clamps += static_cast<std::size_t>(contact[g + 3]);
  }
  const auto counters = counters_.read<std::uint32_t>(counter_count());
  stats.velocity_clamps = counters[0];
  stats.angular_velocity_clamps = counters[1];
  stats.spring_overflows = counters[2];
  stats.bonds_broken = counters[TS_SIM_COUNTER_BONDS_BROKEN];
  const std::uint32_t lost_exclusions = counters[TS_SIM_COUNTER_BOND_EXCLUSIONS_LOST];
  stats.penetration = penetration(counters);
  list_builds_ += counters[TS_SIM_COUNTER_LIST_BUILDS];
  list_overflows_ += counters[TS_SIM_COUNTER_LIST_OVERFLOWS];
  counters_.fill_zero();
  if (bad > 0.0 || !std::isfinite(stats.energy.total())) {
    throw Error(ExitCode::Unstable, fmt::format("simulation unstable at t = {:.6g} s: {} bodies have a non-finite "
                                                "state (reduce dt; see the time-step bound)",
                                                time_, static_cast<std::size_t>(bad)));
  }
  if (lost_exclusions > 0) {
    throw Error(ExitCode::Unstable,
                fmt::format("simulation stopped at t = {:.6g} s: {} bonded spheres had more contact candidates "
                            "than the lists hold (K = {}) and too many bonded partners to list instead; their "
                            "bonded pairs would have met as contacts too (use --backend cpu for this scene)",
                            time_, lost_exclusions, list_capacity_));
  }
  if (stats.penetration.count > 0) throw WallPenetration(time_, stats.penetration);
  // The bonds' elastic energy after the step (the CPU reference reports it at the step's start).
  stats.elastic_energy = bond_energy();
  const double growth = stats.energy.total() + stats.elastic_energy - energy_reference_;
  if (settings_.check_energy && !any_kinematic_ && growth > settings_.energy_growth_tolerance * energy_scale_) {
    throw Error(ExitCode::Unstable,
                fmt::format("simulation unstable at t = {:.6g} s: mechanical energy grew by {:.3g} J with no work "
                            "done (allowed {:.3g} J); reduce dt (see the time-step bound)",
                            time_, growth, settings_.energy_growth_tolerance * energy_scale_));
  }
  return stats;
}

void GpuStepper::download(World& world) const {
  Bodies& b = world.bodies;
  const auto position = read_real(body_position_, 4 * body_count_);
  const auto orientation = read_real(body_orientation_, 4 * body_count_);
  const auto velocity = read_real(body_velocity_, 4 * body_count_);
  const auto omega = read_real(body_omega_, 4 * body_count_);
  const std::vector<std::uint32_t> original = original_ids(original_body_, body_count_);
  for (std::uint32_t k = 0; k < body_count_; ++k) {
    const std::uint32_t w = original[k];
    b.position[w] = {position[4 * k], position[4 * k + 1], position[4 * k + 2]};
    b.orientation[w] = Eigen::Quaterniond(orientation[4 * k + 3], orientation[4 * k], orientation[4 * k + 1],
                                          orientation[4 * k + 2]);
    b.linear_velocity[w] = {velocity[4 * k], velocity[4 * k + 1], velocity[4 * k + 2]};
    b.angular_velocity[w] = {omega[4 * k], omega[4 * k + 1], omega[4 * k + 2]};
  }
  world.time = time_;
  download_springs(world);
  download_bonds(world);
}

// The history slots in the GPU's layout: world.springs as far as it goes (grains appended since
// have none yet), the rest free.
template <typename Slots>
static std::vector<Slots> pack_springs(const World& world, std::size_t particles) {
  std::vector<Slots> out(particles);
  constexpr std::size_t K = ContactSprings::kSlots;
  for (std::size_t i = 0; i < particles; ++i) {
    for (std::size_t s = 0; s < K; ++s) {
      const std::size_t slot = i * K + s;
      const bool known = slot < world.springs.partner.size() && world.springs.partner[slot] != ContactSprings::kNoPartner;
      const std::int64_t partner = known ? world.springs.partner[slot] : TS_SIM_NO_PARTNER;
      (&out[i].partner[s / 4].x)[s % 4] = static_cast<std::int32_t>(partner);
      const Eigen::Vector3d d = known ? world.springs.displacement[slot] : Eigen::Vector3d::Zero();
      out[i].displacement[s] = {static_cast<decltype(out[i].displacement[s].x)>(d.x()),
                                static_cast<decltype(out[i].displacement[s].x)>(d.y()),
                                static_cast<decltype(out[i].displacement[s].x)>(d.z()), 0};
    }
  }
  return out;
}

// GPU slots back into world order: `original` maps GPU particle ids (slot owners and partners) to the
// world's.
template <typename Slots>
static void unpack_springs(const std::vector<Slots>& slots, const std::vector<std::uint32_t>& original,
                           World& world) {
  constexpr std::size_t K = ContactSprings::kSlots;
  world.springs.partner.assign(slots.size() * K, ContactSprings::kNoPartner);
  world.springs.displacement.assign(slots.size() * K, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const std::size_t owner = original[i];
    for (std::size_t s = 0; s < K; ++s) {
      const std::int32_t partner = (&slots[i].partner[s / 4].x)[s % 4];
      if (partner == TS_SIM_NO_PARTNER) continue;
      world.springs.partner[owner * K + s] = partner >= 0 ? std::int64_t{original[static_cast<std::size_t>(partner)]}
                                                          : std::int64_t{partner};
      const auto& d = slots[i].displacement[s];
      world.springs.displacement[owner * K + s] = {d.x, d.y, d.z};
    }
  }
}

void GpuStepper::upload_springs(const World& world) {
  const bool on = settings_.tangential == TangentialModel::Spring;
  const std::size_t n = on ? particle_count_ : 1;  // a placeholder keeps the binding valid
  if (fp64()) {
    springs_ = gpu::Buffer::from<SimSpringSlots64>(pack_springs<SimSpringSlots64>(world, n));
  } else {
    springs_ = gpu::Buffer::from<SimSpringSlots>(pack_springs<SimSpringSlots>(world, n));
  }
}

void GpuStepper::download_springs(World& world) const {
  if (settings_.tangential != TangentialModel::Spring) return;
  const std::vector<std::uint32_t> original = original_ids(original_particle_, particle_count_);
  if (fp64()) {
    unpack_springs(springs_.read<SimSpringSlots64>(particle_count_), original, world);
  } else {
    unpack_springs(springs_.read<SimSpringSlots>(particle_count_), original, world);
  }
}

std::vector<Eigen::Vector3d> GpuStepper::particle_forces() const {
  const auto values = read_real(particle_wrench_, 8 * particle_count_);
  std::vector<Eigen::Vector3d> out(particle_count_);
  const std::vector<std::uint32_t> original = original_ids(original_particle_, particle_count_);
  for (std::uint32_t i = 0; i < particle_count_; ++i) {
    out[original[i]] = {values[8 * i], values[8 * i + 1], values[8 * i + 2]};
  }
  return out;
}

// ---- Re-sorting bodies by cell (memory locality of the neighbour gathers).

void GpuStepper::allocate_resort(std::uint32_t body_count, std::uint32_t particle_count) {
  const std::uint32_t bodies = std::max(body_count, 1u), particles = std::max(particle_count, 1u);
  bucket_table_ = std::bit_ceil(std::max(2u * bodies, 64u));
  const std::size_t word = sizeof(std::uint32_t);
  sort_key_ = gpu::Buffer(bodies * word);
  sort_slot_ = gpu::Buffer(bodies * word);
  order_ = gpu::Buffer(bodies * word);
  new_first_ = gpu::Buffer(bodies * word);
  new_range_ = gpu::Buffer(bodies * 4 * word);
  bucket_count_ = gpu::Buffer(bucket_table_ * word);
  bucket_start_ = gpu::Buffer(bucket_table_ * word);
  source_particle_ = gpu::Buffer(particles * word);
  new_of_old_ = gpu::Buffer(particles * word);
  owner_ = gpu::Buffer(particles * word);
  // The world order, as uvec4 rows (x) so gather() moves them like every other array.
  auto identity = [](std::uint32_t n) {
    std::vector<std::uint32_t> ids(4 * std::size_t{n}, 0u);
    for (std::uint32_t i = 0; i < n; ++i) ids[4 * i] = i;
    return gpu::Buffer::from<std::uint32_t>(ids);
  };
  original_body_ = identity(bodies);
  original_particle_ = identity(particles);
  steps_since_resort_ = 0;
}

std::vector<std::uint32_t> GpuStepper::original_ids(const gpu::Buffer& ids, std::uint32_t count) const {
  const auto rows = ids.read<std::uint32_t>(4 * std::size_t{count});
  std::vector<std::uint32_t> out(count);
  for (std::uint32_t i = 0; i < count; ++i) out[i] = rows[4 * i];
  return out;
}

void GpuStepper::gather(gpu::Buffer& buffer, const gpu::Buffer& index, std::uint32_t rows, std::uint32_t width) {
  gpu::Buffer reordered(buffer.bytes());
  buffer.bind(TS_SIM_GATHER_SOURCE);
  reordered.bind(TS_SIM_GATHER_DESTINATION);
  index.bind(TS_SIM_GATHER_INDEX);
  gather_rows_params_.values.shape = {rows, width, 0u, 0u};
  gather_rows_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(gather_rows_, rows);
  buffer = std::move(reordered);
}

void GpuStepper::resort() {
  steps_since_resort_ = 0;
  if (body_count_ < 2) return;
  // The new body order: counting sort by Morton key, ids ascending within a key (deterministic).
  bucket_count_.fill_zero();
  body_position_.bind(TS_SIM_BODY_POSITION);
  sort_key_.bind(TS_SORT_KEY);
  bucket_count_.bind(TS_SORT_BUCKET_COUNT);
  sort_slot_.bind(TS_SORT_SLOT);
  resort_keys_params_.values = {{body_count_, bucket_table_, 0u, 0u}, {static_cast<float>(cell_size_), 0.0f, 0.0f, 0.0f}};
  resort_keys_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(resort_keys_, body_count_);
  bucket_sort_.finish(queue_, sort_key_, bucket_count_, sort_slot_, bucket_start_, order_, body_count_, bucket_table_);

  // New particle ranges (a scan of the counts in the new order) and the particle maps.
  order_.bind(TS_SIM_RESORT_ORDER);
  body_range_.bind(TS_SIM_BODY_RANGE);
  new_first_.bind(TS_SIM_RESORT_NEW_FIRST);
  resort_bodies_params_.values.count.x = body_count_;
  resort_bodies_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(resort_ranges_, body_count_);
  resort_scan_.run(queue_, new_first_, body_count_);
  order_.bind(TS_SIM_RESORT_ORDER);
  new_first_.bind(TS_SIM_RESORT_NEW_FIRST);
  body_range_.bind(TS_SIM_BODY_RANGE);
  new_range_.bind(TS_SIM_RESORT_NEW_RANGE);
  source_particle_.bind(TS_SIM_RESORT_SOURCE);
  new_of_old_.bind(TS_SIM_RESORT_DESTINATION);
  owner_.bind(TS_SIM_RESORT_OWNER);
  resort_bodies_params_.bind(TS_SIM_PARAMS);  // again: the scan's own parameters took the slot
  queue_.dispatch_items(resort_particles_, body_count_);
  std::swap(body_range_, new_range_);

  // Every persistent array follows (per-step scratch such as forces is recomputed anyway).
  const std::uint32_t r4 = fp64() ? 2 : 1;  // 16-byte words per real4
  for (gpu::Buffer* b : {&body_position_, &body_orientation_, &body_velocity_, &body_omega_, &body_momentum_})
    gather(*b, order_, body_count_, r4);
  gather(body_inverse_inertia_, order_, body_count_, 3 * r4);
  gather(original_body_, order_, body_count_, 1);
  gather(particle_info_, source_particle_, particle_count_, 1);
  gather(particle_local_, source_particle_, particle_count_, r4);
  gather(original_particle_, source_particle_, particle_count_, 1);
  const bool springs = settings_.tangential == TangentialModel::Spring;
  if (springs) {
    const std::uint32_t words = fp64() ? sizeof(SimSpringSlots64) / 16 : sizeof(SimSpringSlots) / 16;
    gather(springs_, source_particle_, particle_count_, words);
  }
  particle_info_.bind(TS_SIM_PARTICLE_INFO);
  new_of_old_.bind(TS_SIM_RESORT_DESTINATION);
  owner_.bind(TS_SIM_RESORT_OWNER);
  springs_.bind(TS_SIM_SPRINGS);
  resort_fixup_params_.values = {{particle_count_, 0u, 0u, 0u}, {springs ? 1 : 0, 0, 0, 0}};
  resort_fixup_params_.bind(TS_SIM_PARAMS);
  queue_.dispatch_items(resort_fixup_, particle_count_);
  if (bond_count_ > 0) rename_bonded_spheres();
  force_list_rebuild();  // the lists name particles by their old index
}

std::size_t GpuStepper::gpu_bytes() const {
  std::size_t total = grid_.bytes();
  for (const gpu::Buffer* b : {&particle_position_, &particle_position_exact_, &particle_velocity_, &particle_info_,
                               &particle_local_, &body_position_, &body_orientation_, &body_velocity_, &body_omega_,
                               &body_inverse_inertia_, &body_range_, &body_momentum_, &particle_wrench_,
                               &springs_, &keyframes_, &pairs_, &planes_, &cylinders_, &particle_stats_buffer_,
                               &list_, &build_position_, &bond_pair_, &bond_csr_, &bond_state_,
                               &bond_constants_, &bond_load_, &bond_energy_factors_, &bond_energy_partials_})
    total += b->bytes();
  return total;
}

StepStats GpuStepper::advance(World& world, std::int64_t steps) {
  if (!loaded_) upload(world);
  step(static_cast<int>(steps));
  const gpu::HostSyncScope counted(output_syncs_);
  ++outputs_;
  download(world);  // first, so that a run stopped by statistics() leaves the offending state in `world`
  return statistics();
}

std::vector<gpu::HostSyncPhase> GpuStepper::round_trips() const {
  return {
      {"sim steps between outputs", step_syncs_, steps_run_, "step"},
      {"outputs (statistics, state read back)", output_syncs_, outputs_, "output"},
      {"in all (uploads, frames, checkpoints, timers)", gpu::host_sync_counts() - syncs_at_start_, 0, ""}};
}

std::string GpuStepper::timing_report() {
  std::string kernels = queue_.timing_report();  // first: its read of the timers is in the total
  std::string lists = list_report();
  return kernels + lists + gpu::host_sync_report(round_trips());
}

std::string GpuStepper::save_state() const {
  ByteWriter w;
  w.put_string(context_.renderer());
  w.put(body_count_);
  w.put(particle_count_);
  if (bond_count_ > 0) w.put(bond_count_);
  w.put(steps_since_resort_);
  for (double v : {time_, energy_reference_, energy_scale_}) w.put(v);
  std::vector<const gpu::Buffer*> buffers;
  for (const gpu::Buffer* b : persistent_buffers(*this)) buffers.push_back(b);
  // The bonds (their spheres' GPU indices, intact flags and loads), only when there are any: the
  // state of a world without bonds is as it was before bonds.
  if (bond_count_ > 0) buffers.insert(buffers.end(), {&bond_pair_, &bond_state_});
  for (const gpu::Buffer* b : buffers) {
    const auto bytes = b->read<char>(b->bytes());
    w.put_string(std::string_view(bytes.data(), bytes.size()));
  }
  return w.bytes();
}

void GpuStepper::restore_state(const World& world, std::string_view state) {
  if (!loaded_) upload(world);
  ByteReader r(state, "the GPU pipeline's state");
  const std::string renderer = r.get_string();
  if (renderer != context_.renderer()) {
    log::warn(
        "the checkpoint was written on {}, this run uses {}: it goes on, but not bit for bit as it would "
        "have "
        "there",
        renderer, context_.renderer());
  }
  if (r.get<std::uint32_t>() != body_count_ || r.get<std::uint32_t>() != particle_count_) {
    r.fail("made for a world of another size");
  }
  if (bond_count_ > 0 && r.get<std::uint32_t>() != bond_count_) r.fail("made for a world with other bonds");
  r.get(steps_since_resort_);
  for (double* v : {&time_, &energy_reference_, &energy_scale_}) r.get(*v);
  std::vector<gpu::Buffer*> buffers;
  for (gpu::Buffer* b : persistent_buffers(*this)) buffers.push_back(b);
  if (bond_count_ > 0) buffers.insert(buffers.end(), {&bond_pair_, &bond_state_});
  for (gpu::Buffer* b : buffers) {
    const std::string bytes = r.get_string();
    if (bytes.size() != b->bytes()) r.fail("a buffer of another size");
    if (!bytes.empty()) b->upload(bytes.data(), bytes.size());
  }
  if (!r.done()) r.fail("bytes left over");
  // The lists are not saved: rebuilt from the restored positions they hold the same candidates in
  // the same ascending order, so the forces, summed over the touching ones, are the same bits.
  force_list_rebuild();
}

std::vector<ContactRecord> GpuStepper::contacts(const World& world) { return CpuContacts(settings_).contacts(world); }

}  // namespace ts::sim
