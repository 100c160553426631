#include "bench/bench_scenes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <utility>

#include "sim/grain.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"

namespace ts::bench {

std::filesystem::path reference_scene(const std::string& name) {
  // A binary carried to another machine (scripts/device-bench.sh) finds the tree there by the variable.
  const char* moved = std::getenv("TETRASAND_SOURCE_DIR");
  const std::filesystem::path root = moved && *moved ? moved : TETRASAND_SOURCE_DIR;
  return root / "assets" / "scenes" / "reference" / name;
}

sim::World settling_box(std::uint32_t grains, std::uint64_t seed) {
  sim::World world;
  sim::Material sand;
  sand.youngs_modulus = 1e7;
  world.materials = {sand};
  const sim::GrainShape grain = sim::make_tetrahedral_grain(0.001, 0.002, sand.density);
  const double spacing = 2.2 * grain.bounding_radius;  // m: lattice spacing, no initial overlap
  const auto side = static_cast<std::uint32_t>(std::ceil(std::sqrt(grains / 4.0)));  // 4 layers deep
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::uint32_t n = 0; n < grains; ++n) {
    const Eigen::Vector3d position(spacing * (0.5 + n % side), spacing * (0.5 + (n / side) % side),
                                   spacing * (0.5 + n / (side * side)));
    const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
    sim::add_grain(world, grain, 0, position, q, 0.05 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  const double width = spacing * side;
  world.walls.planes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0},
                        {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 0},
                        {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 0},
                        {Eigen::Vector3d(width, 0, 0), -Eigen::Vector3d::UnitX(), 0},
                        {Eigen::Vector3d(0, width, 0), -Eigen::Vector3d::UnitY(), 0}};
  return world;
}

BondedBlock bonded_block(std::uint32_t spheres) {
  constexpr double radius = 1e-3;  // m
  BondedBlock out;
  sim::World& world = out.world;
  world.materials = {sim::Material{}};
  const auto n = static_cast<int>(std::max(1.0, std::round(std::cbrt(spheres / 4.0))));
  const double edge = 2.0 * std::sqrt(2.0) * radius;  // the FCC cell of touching spheres
  const Eigen::Vector3d basis[4] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::vector<Eigen::Vector3d> centres;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (const Eigen::Vector3d& b : basis)
          centres.push_back(edge * (Eigen::Vector3d(x, y, z) + b) + Eigen::Vector3d(0, 0, radius));
  const double mass = world.materials[0].density * 4.0 * std::sqrt(2.0) * std::pow(radius, 3);  // a lattice cell's
  for (const Eigen::Vector3d& c : centres) {
    sim::BodyDesc d;
    d.position = c;
    d.inverse_mass = 1.0 / mass;
    d.inverse_inertia = Eigen::Matrix3d::Identity() / (0.4 * mass * radius * radius);
    sim::add_body(world, d, {Eigen::Vector3d::Zero()}, {radius}, 0);
  }
  sim::BondMaterial cement;
  cement.youngs_modulus = 1e8;
  cement.tensile_strength = cement.shear_strength = 1e12;  // Pa: never breaks here
  const std::vector<double> radii(centres.size(), radius);
  world.bonds = sim::build_bonds(centres, radii, cement, 1);
  world.bond_materials = {cement};
  world.walls.planes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0}};
  out.dt = sim::bond_time_step(world.bonds, std::vector<double>(centres.size(), mass), radii, cement);
  return out;
}

std::string grain_centres_csv(const sim::World& world) {
  std::string csv = "x_m,y_m,z_m\n";
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] != sim::MotionType::Dynamic) continue;
    const Eigen::Vector3d& x = world.bodies.position[b];
    csv += fmt::format("{:.6e},{:.6e},{:.6e}\n", x.x(), x.y(), x.z());
  }
  return csv;
}

BenchWorld settle(const scene::Scene& scene) {
  BenchWorld out{scene::make_world(scene), scene.simulation.step};
  out.settings.dt = scene::resolve_time_step(scene, out.world, nullptr);
  sim::CpuStepper stepper(out.world, out.settings);
  const auto steps = static_cast<std::int64_t>(std::ceil(scene.simulation.duration / out.settings.dt));
  for (std::int64_t s = 0; s < steps; ++s) stepper.step(out.world);
  return out;
}

namespace {

// Appends a copy of `body` of `from`, shifted by `shift`, to `to`.
void copy_body(const sim::World& from, std::size_t body, const Eigen::Vector3d& shift, sim::World& to) {
  const sim::Bodies& b = from.bodies;
  sim::BodyDesc desc;
  desc.position = b.position[body] + shift;
  desc.orientation = b.orientation[body];
  desc.linear_velocity = b.linear_velocity[body];
  desc.angular_velocity = b.angular_velocity[body];
  desc.inverse_mass = b.inverse_mass[body];
  desc.inverse_inertia = b.inverse_inertia[body];
  desc.motion = b.motion[body];
  std::vector<Eigen::Vector3d> offsets;
  std::vector<double> radii;
  for (std::uint32_t p = b.first_particle[body]; p < b.first_particle[body] + b.particle_count[body]; ++p) {
    offsets.push_back(from.particles.offset[p]);
    radii.push_back(from.particles.radius[p]);
  }
  sim::add_body(to, desc, offsets, radii, from.particles.material[b.first_particle[body]]);
}

// The most nearly square grid nx x ny holding `tiles`: a divisor pair when one is close to square,
// else ceil(sqrt) columns with a partly filled last row.
std::pair<std::size_t, std::size_t> tile_grid(std::size_t tiles) {
  const auto root = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(tiles))));
  for (std::size_t nx = root; 2 * nx >= root; --nx) {
    if (tiles % nx == 0) return {nx, tiles / nx};
  }
  return {root, (tiles + root - 1) / root};
}

}  // namespace

BenchWorld settled_bed(std::uint32_t grains) {
  struct Tile {
    scene::Scene scene;
    BenchWorld settled;
  };
  static const Tile tile = [] {
    Tile t{scene::load_scene(reference_scene("bed_tile.toml")), {}};
    t.settled = settle(t.scene);
    return t;
  }();
  const scene::Boundary& box = tile.scene.boundaries.at(0);
  const Eigen::Vector3d extent = box.max - box.min;
  const sim::World& source = tile.settled.world;
  const std::size_t tiles = std::max<std::size_t>(1, grains / source.bodies.size());
  const auto [nx, ny] = tile_grid(tiles);
  BenchWorld out;
  out.settings = tile.settled.settings;
  out.world.materials = source.materials;
  out.world.gravity = source.gravity;
  for (std::size_t t = 0; t < tiles; ++t) {
    const Eigen::Vector3d shift(extent.x() * static_cast<double>(t % nx), extent.y() * static_cast<double>(t / nx), 0);
    for (std::size_t b = 0; b < source.bodies.size(); ++b) copy_body(source, b, shift, out.world);
  }
  const Eigen::Vector3d lo = box.min;
  const Eigen::Vector3d hi = box.min + Eigen::Vector3d(extent.x() * static_cast<double>(nx),
                                                       extent.y() * static_cast<double>(ny), extent.z());
  out.world.walls.planes = {{lo, Eigen::Vector3d::UnitZ(), box.material},
                            {lo, Eigen::Vector3d::UnitX(), box.material},
                            {lo, Eigen::Vector3d::UnitY(), box.material},
                            {hi, -Eigen::Vector3d::UnitX(), box.material},
                            {hi, -Eigen::Vector3d::UnitY(), box.material}};
  return out;
}

BenchWorld ploughed_bed(std::uint32_t grains, double speed) {
  const BenchWorld bed = settled_bed(grains);
  const sim::World& source = bed.world;
  const sim::Bodies& b = source.bodies;
  const Eigen::Vector3d lo = source.walls.planes.at(0).point;  // the box's low corner (settled_bed's walls)
  const Eigen::Vector3d hi = source.walls.planes.at(3).point;  // its high corner in x and y
  double radius = 0, top = lo.z();                             // m: largest particle radius, the bed's top
  for (std::size_t p = 0; p < source.particles.size(); ++p)
    radius = std::max(radius, source.particles.radius[p]);
  for (std::size_t k = 0; k < b.size(); ++k) top = std::max(top, b.position[k].z() + b.bounding_radius[k]);
  const double blade_x = lo.x() + 0.25 * (hi.x() - lo.x());
  const double spacing = 1.5 * radius;  // m: gaps of half a radius, far narrower than a grain
  BenchWorld out;
  out.settings = bed.settings;
  out.settings.design_speed = std::max(out.settings.design_speed, speed);
  out.world.materials = source.materials;
  out.world.gravity = source.gravity;
  out.world.walls = source.walls;
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < b.size(); ++k) {
    // The slot: grains within reach of the blade's spheres, with a tenth of a radius to spare.
    if (std::abs(b.position[k].x() - blade_x) < b.bounding_radius[k] + 1.1 * radius) continue;
    copy_body(source, k, none, out.world);
  }
  sim::BodyDesc sphere;
  sphere.motion = sim::MotionType::Kinematic;
  sphere.linear_velocity = Eigen::Vector3d(speed, 0, 0);
  for (double y = lo.y() + radius; y <= hi.y() - radius; y += spacing) {
    for (double z = lo.z() + 1.1 * radius; z <= top + 2e-3; z += spacing) {
      sphere.position = Eigen::Vector3d(blade_x, y, z);
      sim::add_body(out.world, sphere, {none}, {radius}, 0);
    }
  }
  return out;
}

}  // namespace ts::bench
