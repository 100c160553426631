#include "scene/scene_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "sim/grain.h"
#include "scene/grain_mix.h"

namespace ts::scene {
namespace {

// Criterion 1: the Hertz static overlap under one grain's weight against the overlap clamp.
void check_weight(const Scene& scene, const World& world, const WorldSources& sources) {
  const double g = scene.gravity.norm();  // m/s^2
  if (g == 0) return;
  const double ratio = scene.simulation.step.max_overlap_ratio;
  for (const SceneContactCase& c : scene_contact_cases(scene, world, &sources)) {
    const double k_n =
        4.0 / 3.0 * c.contact.effective_modulus * std::sqrt(c.contact.effective_radius);  // N/m^1.5
    const double resting = std::pow(c.load_mass * g / k_n, 2.0 / 3.0);                    // m
    const double cap = (ratio > 0 ? ratio : 1.0) * c.smaller_radius;                      // m
    if (resting <= cap) continue;
    const std::string limit =
        ratio > 0 ? fmt::format("the overlap clamp at {:.3g} m ({} of the smaller radius)", cap, ratio)
                  : fmt::format("the radius {:.3g} m", cap);
    throw InputError(fmt::format(
        "{}: |g| = {:.3g} m/s^2 presses {} resting on {} {:.3g} m into it, past {}: no contact can hold "
        "a "
        "grain's own weight, so grains sink through walls and each other whatever the time step; at most "
        "|g| = {:.3g} m/s^2 fits these materials (or stiffer ones: larger E)",
        scene_location(scene, "gravity"), g, c.grain, c.partner, resting, limit,
        g * std::pow(cap / resting, 1.5)));
  }
}

// Criterion 2: with the automatic step, the design impact's travel in one step against the CFL distance.
void check_impact(const Scene& scene, const World& world, double dt) {
  if (scene.simulation.dt > 0) return;  // a dt given by hand warns (resolve_time_step) and runs
  // The grid cell follows the largest particle; without the CFL clamp the smallest grain's radius is
  // the travel a contact can take unseen.
  double radius = 0, smallest = 1e300;  // m
  for (const GrainKind& k : scene_grain_kinds(scene)) {
    radius = std::max(radius, k.shape.particle_radius);
    smallest = std::min(smallest, k.shape.particle_radius);
  }
  for (double r : world.particles.radius) radius = std::max(radius, r);
  const double cfl = scene.simulation.step.cfl;
  const double reach = cfl > 0 ? cfl * 2 * radius : smallest;  // m per step
  const DesignSpeed design = scene_design_speed(scene, world);
  if (design.speed * dt <= reach) return;
  // The largest speed v with v dt(v) <= reach: v dt(v) grows with v (dt falls as v^-1/5 at most).
  double lo = 0, hi = design.speed;
  for (int i = 0; i < 60; ++i) {
    const double v = 0.5 * (lo + hi);
    (v * scene_time_step_bound(scene, world, v).recommended <= reach ? lo : hi) = v;
  }
  const std::string distance =
      cfl > 0 ? fmt::format("the CFL distance {:.3g} m ({} grid cells of {:.3g} m)", reach, cfl, 2 * radius)
              : fmt::format("the smallest grain radius {:.3g} m", reach);
  throw InputError(fmt::format(
      "{}: impacts at the design speed {:.3g} m/s move a grain {:.3g} m in one automatic step of {:.3g} s, "
      "farther "
      "than {}: the step cannot resolve such an impact (the contact is never seen, the velocity clamp would "
      "cut "
      "it); at most {:.3g} m/s fits (simulation.max_impact_speed states the real largest impact speed)",
      scene_location(scene, design.key, design.line), design.speed, design.speed * dt, dt, distance, lo));
}

}  // namespace

void check_scene_forces(const Scene& scene, const World& world, const WorldSources& sources, double dt) {
  check_weight(scene, world, sources);
  check_impact(scene, world, dt);
}

namespace {

// The first smooth wall (planes, then cylinders, as the engines number them) the sphere at x of
// radius r lies wholly behind; -1 when none.
std::int64_t wall_passed(const Walls& walls, const Eigen::Vector3d& x, double r) {
  for (std::size_t w = 0; w < walls.planes.size(); ++w) {
    const PlaneWall& p = walls.planes[w];
    if (p.normal.dot(x - p.point) < -r) return static_cast<std::int64_t>(w);
  }
  for (std::size_t c = 0; c < walls.cylinders.size(); ++c) {
    const CylinderWall& w = walls.cylinders[c];
    if (x.z() < w.z_min || x.z() > w.z_max) continue;
    if ((x.head<2>() - w.axis).norm() > w.radius + r)
      return static_cast<std::int64_t>(walls.planes.size() + c);
  }
  return -1;
}

}  // namespace

Penetration find_wall_penetration(const World& world) {
  Penetration found;
  if (world.walls.planes.empty() && world.walls.cylinders.empty()) return found;
  const std::vector<Eigen::Vector3d> positions = particle_positions(world);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (world.bodies.motion[world.particles.body[i]] != MotionType::Dynamic) continue;
    const std::int64_t wall = wall_passed(world.walls, positions[i], world.particles.radius[i]);
    if (wall < 0 || found.count++ > 0) continue;
    found.particle = static_cast<std::uint32_t>(i);
    found.wall = wall;
  }
  return found;
}

void ClampWatch::interval(std::size_t clamps, std::int64_t steps, double time) {
  const bool saturated = steps > 0 && clamps >= static_cast<std::size_t>(steps);
  const State before = std::exchange(state_, State{clamps, saturated});
  if (!enabled_ || !saturated || !before.saturated || clamps < before.clamps) return;
  throw Error(
      ExitCode::Unstable,
      fmt::format(
          "simulation unstable at t = {:.6g} s: {} velocity clamps in the last {} steps, after {} in the "
          "interval before: bodies are driven past the CFL speed step after step, so their motion is "
          "no longer the scene's (reduce dt, or check the forces; check_clamps = false runs on)",
          time, clamps, steps, before.clamps));
}

std::string describe_penetration(const WallPenetration& e, const World& world, const WorldSources& sources) {
  const Penetration& p = e.penetration();
  const std::uint32_t body = world.particles.body[p.particle];
  const std::string who =
      body < sources.bodies.size() ? sources.bodies[body] : fmt::format("grain body {}", body);
  const auto w = static_cast<std::size_t>(p.wall);
  const std::string wall =
      w < sources.smooth_walls.size() ? sources.smooth_walls[w] : fmt::format("smooth wall {}", w);
  const Eigen::Vector3d x =
      world.bodies.position[body] + world.bodies.orientation[body] * world.particles.offset[p.particle];
  return fmt::format(
      "simulation unstable at t = {:.6g} s: particle {} of {} has passed through {} (its sphere is "
      "wholly behind the wall's surface; now at ({:.4g}, {:.4g}, {:.4g}) m): the contact did not stop "
      "it, an impact faster than the time step resolves or a force no contact holds "
      "(docs/reliability.md)",
      e.time(), p.particle, who, wall, x.x(), x.y(), x.z());
}

}  // namespace ts::scene
