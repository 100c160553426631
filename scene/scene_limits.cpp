// Size checks of a scene before make_world allocates: each count is computed in double from the keys
// with the formulas the world builders use (scene/scene_world.cpp), then compared with its limit.
#include "scene/scene_limits.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/checked_values.h"
#include "core/error.h"
#include "scene/grain_mix.h"
#include "scene/lattice.h"

namespace ts::scene {
namespace {

[[noreturn]] void fail(const Scene& scene, int line, std::string_view key, const std::string& problem) {
  throw InputError(fmt::format("{}: {}", scene_location(scene, key, line), problem));
}

// The edge of the largest cube of lattice sites that fits (m).
double largest_cube(double spacing, double bound) {
  return std::cbrt(kMaxLatticeSites) * spacing + 2.2 * bound;
}

void check_lattice(const Scene& scene, const Emitter& e, double sites, std::string_view key, double bound) {
  if (sites <= kMaxLatticeSites) return;
  const double spacing = lattice_spacing(bound);
  fail(
      scene, e.line, key,
      fmt::format(
          "the region holds {:.3g} lattice sites (spacing {:.3g} m, {} grains asked for); at most {:.0f} fit "
          "(a box of at most {:.3g} m on a side)",
          sites, spacing, e.count, kMaxLatticeSites, largest_cube(spacing, bound)));
}

void check_emitter(const Scene& scene, const Emitter& e, double bound) {
  // The lattice is bounded before any loop over it: a grain radius of 1e308 made its spacing infinite,
  // the site counts below 0, and a column's layer loop never ended (issue 46).
  if (!(bound > 0) || !std::isfinite(lattice_spacing(bound))) {
    fail(scene, e.line, "emitter",
         fmt::format(
             "its largest grain is {:.3g} m in bounding radius (the [grain] radius and edge times the size "
             "scale), so its lattice spacing (2.2 times that) is not a finite length; every size must be "
             "finite and positive",
             bound));
  }
  const double particles = 4.0 * static_cast<double>(e.count);
  if (particles > kMaxParticles) {
    fail(scene, e.line, "emitter.count",
         fmt::format("{} grains are {:.3g} particles; at most {:.0f} grains fit", e.count, particles,
                     kMaxParticles / 4));
  }
  if (e.type != EmitterType::Column) {
    check_lattice(scene, e, lattice_site_count(e.min, e.max, bound), "emitter.max", bound);
    return;
  }
  // A column grows a layer at a time: one layer of its square, then about as many layers as the
  // count needs (pi/4 of a layer's sites lie in the circle).
  const Eigen::Vector3d half(e.radius, e.radius, 0), top(0, 0, lattice_spacing(bound));
  const double layer = lattice_site_count(e.centre - half, e.centre + half + top, bound);
  check_lattice(scene, e, layer, "emitter.radius", bound);
  const double layers =
      std::ceil(static_cast<double>(e.count) / std::max(1.0, std::floor(layer * std::numbers::pi / 4)));
  check_lattice(scene, e, layer * layers, "emitter.count", bound);
}

// Particles of a rough rectangle (tops in a plane) of `size` at `spacing`, with the rim of a round hole.
double rough_rectangle_particles(const Eigen::Vector2d& size, double spacing, double hole_radius,
                                 bool round_rim, double radius) {
  const double n = (std::floor(size.x() / spacing) + 1) * (std::floor(size.y() / spacing) + 1);
  if (!round_rim) return n;
  return n + std::max(3.0, std::ceil(2 * std::numbers::pi * (hole_radius + radius) / radius));
}

// Particles of a rough boundary, and the key that sets their number.
std::pair<double, std::string_view> rough_particles(const Boundary& b) {
  switch (b.type) {
    case BoundaryType::Plane:
      return {rough_rectangle_particles(b.size, b.spacing, b.hole_radius, b.round_rim, b.particle_radius),
              b.round_rim && b.hole_radius > b.size.maxCoeff() ? "boundary.hole_radius" : "boundary.size"};
    case BoundaryType::Box: {
      const Eigen::Vector3d e = b.max - b.min;
      auto face = [&](double a, double c) {
        return rough_rectangle_particles({a, c}, b.spacing, 0, false, 0);
      };
      return {face(e.x(), e.y()) + 2 * face(e.y(), e.z()) + 2 * face(e.x(), e.z()), "boundary.max"};
    }
    case BoundaryType::Cylinder: {
      const double around = std::ceil(2 * std::numbers::pi * (b.radius + b.particle_radius) / b.spacing);
      const double up = std::floor((b.z_max - b.z_min) / b.spacing) + 1;
      return {around * up, up > around ? "boundary.z_max" : "boundary.radius"};
    }
  }
  return {0.0, ""};
}

void check_total(const Scene& scene, double grains, double others, std::string_view what) {
  if (4 * grains + others <= kMaxParticles) return;
  throw InputError(
      fmt::format("{}: the scene needs {:.3g} particles ({:.3g} grains of 4, {:.3g} in {}); at most {:.0f} "
                  "fit",
                  scene.file.string(), 4 * grains + others, grains, others, what, kMaxParticles));
}

double total_grains(const Scene& scene) {
  double grains = 0;
  for (const Emitter& e : scene.emitters) grains += static_cast<double>(e.count);
  return grains;
}

void check_cell(const Scene& scene, int line, std::string_view key, const Eigen::Vector3d& point,
                double cell) {
  const double farthest = point.cwiseAbs().maxCoeff();  // m
  if (farthest / cell <= kMaxCellCoordinate) return;
  fail(scene, line, key,
       fmt::format(
           "lies {:.3g} m from the origin, {:.3g} grid cells of {:.3g} m (the largest particle diameter); at "
           "most {:.0g} cells fit (within {:.3g} m of the origin)",
           farthest, farthest / cell, cell, kMaxCellCoordinate, kMaxCellCoordinate * cell));
}

void check_boundary_cells(const Scene& scene, const Boundary& b, double cell) {
  if (!b.rough) return;  // smooth walls hold no particles
  switch (b.type) {
    case BoundaryType::Plane: {
      const Eigen::Vector3d reach = Eigen::Vector3d::Constant(0.5 * b.size.maxCoeff());
      check_cell(scene, b.line, "boundary.point", b.point.cwiseAbs() + reach, cell);
      break;
    }
    case BoundaryType::Box:
      check_cell(scene, b.line, "boundary.min", b.min, cell);
      check_cell(scene, b.line, "boundary.max", b.max, cell);
      break;
    case BoundaryType::Cylinder: {
      const Eigen::Vector2d reach =
          b.axis.cwiseAbs() + Eigen::Vector2d::Constant(b.radius + b.particle_radius);
      check_cell(scene, b.line, "boundary.radius", Eigen::Vector3d(reach.x(), reach.y(), 0), cell);
      check_cell(scene, b.line, "boundary.z_min", Eigen::Vector3d(0, 0, b.z_min), cell);
      check_cell(scene, b.line, "boundary.z_max", Eigen::Vector3d(0, 0, b.z_max), cell);
      break;
    }
  }
}

void check_emitter_cells(const Scene& scene, const Emitter& e, double cell) {
  if (e.type == EmitterType::Column) {
    check_cell(scene, e.line, "emitter.centre", e.centre.cwiseAbs() + Eigen::Vector3d(e.radius, e.radius, 0),
               cell);
  } else {
    check_cell(scene, e.line, "emitter.min", e.min, cell);
    check_cell(scene, e.line, "emitter.max", e.max, cell);
  }
}

// A grain's mass and inertia within core/checked_values.h's mass range: density = 1e200 made a run
// write a NaN rotational energy at exit 0 (found by fuzz_scene).
void check_grain_mass(const Scene& scene, const GrainKind& kind) {
  const GrainShape& g = kind.shape;
  if (mass_fits(g.mass) && mass_fits(g.inertia)) return;
  const GrainSpec& spec = scene.grains[kind.type];
  fail(scene, spec.line, "grain",
       fmt::format("{} weighs {:.3g} kg with a moment of inertia of {:.3g} kg m^2 (density {:.3g} kg/m^3, radius "
                   "{:.3g} m); the rigid-body arithmetic needs both within {:.0e}..{:.0e} (use SI units and a "
                   "density and radius of that order)",
                   kind.name, g.mass, g.inertia, scene.materials[spec.material].density, g.particle_radius,
                   kLeastMass, kMostMass));
}

}  // namespace

void check_scene_sizes(const Scene& scene) {
  for (const Emitter& e : scene.emitters) check_emitter(scene, e, emitter_bound(scene, e));
  for (const GrainKind& kind : scene_grain_kinds(scene)) check_grain_mass(scene, kind);
  double rough = 0;
  for (const Boundary& b : scene.boundaries) {
    if (!b.rough) continue;
    const auto [particles, key] = rough_particles(b);
    if (particles > kMaxParticles) {
      fail(scene, b.line, key,
           fmt::format("the rough boundary needs {:.3g} particles (spacing {:.3g} m); at most {:.0f} fit",
                       particles, b.spacing, kMaxParticles));
    }
    rough += particles;
  }
  check_total(scene, total_grains(scene), rough, "rough boundaries");
}

double implied_particles(const Scene& scene) {
  double particles = 4 * total_grains(scene);
  for (const Boundary& b : scene.boundaries)
    if (b.rough) particles += rough_particles(b).first;
  return particles;
}

void check_world_sizes(const Scene& scene, const World& world,
                       const std::vector<std::uint32_t>& prop_bodies) {
  check_total(scene, total_grains(scene), static_cast<double>(world.particles.size()),
              "rough boundaries and props");
  double radius = 0;  // m: the grid cell is the largest particle's diameter
  for (const GrainKind& k : scene_grain_kinds(scene)) radius = std::max(radius, k.shape.particle_radius);
  for (double r : world.particles.radius) radius = std::max(radius, r);
  const double cell = 2 * radius;
  for (const Emitter& e : scene.emitters) check_emitter_cells(scene, e, cell);
  for (const Boundary& b : scene.boundaries) check_boundary_cells(scene, b, cell);
  for (std::size_t i = 0; i < scene.props.size(); ++i) {
    const Prop& p = scene.props[i];
    check_cell(scene, p.line, "prop.position", p.position, cell);
    for (const Keyframe& k : p.keyframes) check_cell(scene, p.line, "prop.keyframes", k.position, cell);
    // The body's particles lie within its bounding radius of its centre: one 1e38 m out in the body's
    // particle file is as far from the origin as a prop placed there.
    if (i >= prop_bodies.size()) continue;
    const double reach = world.bodies.bounding_radius[prop_bodies[i]];
    check_cell(scene, p.line, "prop.body", p.position.cwiseAbs() + Eigen::Vector3d::Constant(reach), cell);
  }
}

}  // namespace ts::scene
