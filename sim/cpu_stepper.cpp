#include "sim/cpu_stepper.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "sim/cpu_bonds.h"
#include "sim/cpu_parallel.h"
#include "sim/state_bytes.h"

namespace ts::sim {

CpuStepper::CpuStepper(const StepSettings& settings) : settings_(settings), contacts_(settings) {}

CpuStepper::CpuStepper(const World& world, const StepSettings& settings) : CpuStepper(settings) {
  reset_energy_reference(world);
}

void CpuStepper::load(const World& world) {
  // As a new stepper would: the pair table rebuilt, the energy reference taken again.
  contacts_.set_materials(world, true);
  contacts_.invalidate_lists();
  reset_energy_reference(world);
}

void CpuStepper::reset_energy_reference(const World& world) {
  contacts_.set_materials(world);
  material_count_ = world.materials.size();
  dynamic_mass_ = 0;
  max_diameter_ = 0;
  for (std::size_t i = 0; i < world.bodies.size(); ++i) {
    if (world.bodies.motion[i] == MotionType::Dynamic) dynamic_mass_ += 1.0 / world.bodies.inverse_mass[i];
  }
  for (double r : world.particles.radius) max_diameter_ = std::max(max_diameter_, 2 * r);
  reference_pending_ = true;  // taken at the next step, when the contacts' spring energy is known
}

StepStats CpuStepper::advance(World& world, std::int64_t steps) {
  StepStats last, sums;
  for (std::int64_t i = 0; i < steps; ++i) {
    // Only the last step's energy is returned; the others' would be computed for nothing.
    last = step_once(world, i + 1 == steps);
    sums.velocity_clamps += last.velocity_clamps;
    sums.angular_velocity_clamps += last.angular_velocity_clamps;
    sums.overlap_clamps += last.overlap_clamps;
    sums.spring_overflows += last.spring_overflows;
    sums.bonds_broken += last.bonds_broken;
  }
  last.bonds_broken = sums.bonds_broken;
  last.spring_overflows = sums.spring_overflows;
  last.velocity_clamps = sums.velocity_clamps;
  last.angular_velocity_clamps = sums.angular_velocity_clamps;
  last.overlap_clamps = sums.overlap_clamps;
  return last;
}

// The energy check's reference is all the stepper keeps between steps that a resume needs. The
// contact lists are derived: each particle's forces are summed by increasing partner id whatever the
// build the lists come from, so a resumed run rebuilds them at its first step and steps on bit for bit.
std::string CpuStepper::save_state() const {
  ByteWriter w;
  w.put<std::uint64_t>(material_count_);
  for (double v : {energy_reference_, energy_scale_, dynamic_mass_, max_diameter_}) w.put(v);
  w.put<std::uint8_t>(reference_pending_ ? 1 : 0);
  return w.bytes();
}

void CpuStepper::restore_state(const World& world, std::string_view state) {
  ByteReader r(state, "the CPU reference's state");
  if (r.get<std::uint64_t>() != world.materials.size()) r.fail("made for another world's materials");
  for (double* v : {&energy_reference_, &energy_scale_, &dynamic_mass_, &max_diameter_}) r.get(*v);
  reference_pending_ = r.get<std::uint8_t>() != 0;
  if (!r.done()) r.fail("bytes left over");
  contacts_.invalidate_lists();
}

std::vector<ContactRecord> CpuStepper::contacts(const World& world) {
  if (world.materials.size() != material_count_) reset_energy_reference(world);
  return contacts_.contacts(world);
}

namespace {

// q + 1/2 [w, 0] q dt, normalised (eq. 3.50).
Eigen::Quaterniond advance_orientation(const Eigen::Quaterniond& q, const Eigen::Vector3d& w, double dt) {
  const Eigen::Quaterniond spin = Eigen::Quaterniond(0.0, w.x(), w.y(), w.z()) * q;
  Eigen::Quaterniond next(q.coeffs() + 0.5 * dt * spin.coeffs());
  next.normalize();
  return next;
}

// I(t)^-1 = R I0^-1 R^T (eq. 3.48).
Eigen::Matrix3d world_inverse_inertia(const Eigen::Quaterniond& q, const Eigen::Matrix3d& body_inverse_inertia) {
  const Eigen::Matrix3d r = q.toRotationMatrix();
  return r * body_inverse_inertia * r.transpose();
}

}  // namespace

void CpuStepper::integrate(World& world, StepStats& stats) {
  Bodies& b = world.bodies;
  const double dt = settings_.dt;
  // The CFL cell is the largest particle diameter (the lists' grid cell adds the skin).
  const double cell = contacts_.lists().largest_diameter();                      // m
  const double max_speed = settings_.cfl > 0 ? settings_.cfl * cell / dt : 1e300;  // m/s
  const auto count = static_cast<std::uint32_t>(b.size());
  clamped_.assign(count, 0);  // bit 0: linear, bit 1: angular

  for_each_index(count, [&](std::uint32_t k) {
    if (b.motion[k] == MotionType::Static) return;
    if (b.motion[k] == MotionType::Kinematic) {
      b.position[k] += b.linear_velocity[k] * dt;
      b.orientation[k] = advance_orientation(b.orientation[k], b.angular_velocity[k], dt);
      return;
    }
    // Per-body sums in particle order (deterministic).
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
    const std::vector<Eigen::Vector3d>& position = contacts_.positions();
    for (std::uint32_t i = b.first_particle[k]; i < b.first_particle[k] + b.particle_count[k]; ++i) {
      force += forces_.force[i];
      torque += (position[i] - b.position[k]).cross(forces_.force[i]) + forces_.torque[i];
    }
    const Eigen::Vector3d acceleration = world.gravity + b.inverse_mass[k] * force;
    // Rotation first (eqs. 3.47-3.50) through the angular momentum, which is what the torque
    // changes; for the isotropic grains this is plain w += I^-1 tau dt.
    Eigen::Vector3d w_move = b.angular_velocity[k], w;
    if (const double c = isotropic_inverse_inertia(b.inverse_inertia[k]); c > 0) {
      // I^-1 = c Id in every frame (R c Id R^T = c Id): the angular momentum's update w / c + tau dt
      // is w + c tau dt, with no rotation of the tensor and no inverse.
      w = b.angular_velocity[k] + (c * dt) * torque;
      if (settings_.integrator == Integrator::SemiImplicitEuler) w_move = w;
      b.orientation[k] = advance_orientation(b.orientation[k], w_move, dt);
    } else {
      const Eigen::Matrix3d inverse_inertia_now = world_inverse_inertia(b.orientation[k], b.inverse_inertia[k]);
      const Eigen::Vector3d momentum = inverse_inertia_now.inverse() * b.angular_velocity[k] + torque * dt;
      if (settings_.integrator == Integrator::SemiImplicitEuler) w_move = inverse_inertia_now * momentum;
      b.orientation[k] = advance_orientation(b.orientation[k], w_move, dt);
      w = world_inverse_inertia(b.orientation[k], b.inverse_inertia[k]) * momentum;
    }

    Eigen::Vector3d v = b.linear_velocity[k] + acceleration * dt;
    const Eigen::Vector3d v_move = settings_.integrator == Integrator::SemiImplicitEuler ? v : b.linear_velocity[k];
    b.position[k] += v_move * dt;

    const double reach = b.bounding_radius[k];
    if (v.norm() > max_speed) {
      v *= max_speed / v.norm();
      clamped_[k] |= 1;
    }
    if (w.norm() * reach > max_speed) {
      w *= max_speed / (w.norm() * reach);
      clamped_[k] |= 2;
    }
    if (settings_.angular_damping_rate > 0 && v.norm() + w.norm() * reach < settings_.angular_damping_speed) {
      w *= std::max(0.0, 1.0 - settings_.angular_damping_rate * dt);
    }
    b.linear_velocity[k] = v;
    b.angular_velocity[k] = w;
  });
  for (std::uint8_t c : clamped_) {
    stats.velocity_clamps += c & 1;
    stats.angular_velocity_clamps += (c >> 1) & 1;
  }
}

void CpuStepper::check_stability(const World& world, double mechanical_energy, const StepStats& stats) const {
  const Bodies& b = world.bodies;
  bool any_kinematic = false;
  for (std::size_t k = 0; k < b.size(); ++k) {
    any_kinematic |= b.motion[k] == MotionType::Kinematic;
    const bool finite = b.position[k].allFinite() && b.linear_velocity[k].allFinite() &&
                        b.angular_velocity[k].allFinite() && b.orientation[k].coeffs().allFinite();
    if (!finite) {
      throw Error(ExitCode::Unstable, fmt::format("simulation unstable at t = {:.6g} s: body {} has a non-finite "
                                                  "state (reduce dt; see the time-step bound)",
                                                  world.time, k));
    }
  }
  // A finite state can still hold a NaN energy (an inertia that overflows); the growth test below would
  // pass it, as every comparison with NaN is false.
  if (!std::isfinite(mechanical_energy) || !std::isfinite(stats.energy.total())) {
    throw Error(ExitCode::Unstable, fmt::format("simulation unstable at t = {:.6g} s: the mechanical energy is not "
                                                "finite (reduce dt; see the time-step bound)",
                                                world.time));
  }
  if (stats.penetration.count > 0) throw WallPenetration(world.time, stats.penetration);
  if (!settings_.check_energy || any_kinematic) return;  // kinematic bodies do work on the system
  const double growth = mechanical_energy - energy_reference_;
  if (!(growth <= settings_.energy_growth_tolerance * energy_scale_)) {
    throw Error(ExitCode::Unstable,
                fmt::format("simulation unstable at t = {:.6g} s: mechanical energy grew by {:.3g} J with no work "
                            "done (allowed {:.3g} J); reduce dt (see the time-step bound)",
                            world.time, growth, settings_.energy_growth_tolerance * energy_scale_));
  }
}

// The bonds' loads join the contacts' (sim/cpu_bonds.h). A bond that broke leaves its pair to the
// contact law, which the lists left it out of: they are rebuilt at the next step.
void CpuStepper::add_bonds(World& world, StepStats& stats) {
  const BondStep bonds = add_bond_loads(world, contacts_.positions(), settings_.dt, forces_.force, forces_.torque);
  stats.elastic_energy += bonds.energy;
  stats.bonds_broken = bonds.broke;
  if (bonds.broke > 0) contacts_.invalidate_lists();
}

StepStats CpuStepper::step(World& world) { return step_once(world, true); }

StepStats CpuStepper::step_once(World& world, bool energy_after) {
  if (world.materials.size() != material_count_) reset_energy_reference(world);
  StepStats stats;
  apply_tracks(world, world.time);  // keyframed bodies start the step on their track
  contacts_.gather(world, forces_, stats);
  if (settings_.tangential == TangentialModel::Spring) std::swap(world.springs, forces_.springs);
  if (!world.bonds.a.empty()) add_bonds(world, stats);
  // Kinetic + potential + spring energy at the start of the step: what the contacts may only lose.
  const Energy start = energy(world);
  const double mechanical = start.total() + stats.elastic_energy;  // J
  if (reference_pending_) {
    energy_reference_ = mechanical;
    // Allowed growth scale: the energy in motion and springs, plus lifting everything by one
    // diameter and a 1 cm/s stir, so a bed at rest without gravity still has a finite scale.
    energy_scale_ = start.translational + start.rotational + stats.elastic_energy +
                    dynamic_mass_ * (world.gravity.norm() * max_diameter_ + 1e-4);
    reference_pending_ = false;
  }
  integrate(world, stats);
  apply_tracks(world, world.time + settings_.dt);  // and end it there, with the velocities of that time
  world.time += settings_.dt;
  // The energy after the step is the next step's start energy, which that step takes (and checks) itself.
  if (energy_after) stats.energy = energy(world);
  check_stability(world, mechanical, stats);
  return stats;
}

}  // namespace ts::sim
