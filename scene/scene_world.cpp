// From a parsed scene to the initial World: walls (smooth planes/cylinders, or rough particle
// lattices as static bodies), props, and grains placed by the emitters.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "body/body_file.h"
#include "core/error.h"
#include "scene/scene_limits.h"
#include "scene/scene_world.h"

namespace ts::scene {
namespace {

Eigen::Quaterniond random_orientation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  // Four independent normals, normalised: uniform over rotations.
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized();
}

std::string where(const Scene& scene, int line, std::string_view key) {
  return fmt::format("{}:{}: {}", scene.file.string(), line, key);
}

// A static body of touching (or `spacing`-spaced) spheres on a rectangular lattice whose tops lie
// in the plane through `surface` with normal n; particles reaching into the hole are left out, and
// a round rim lines the hole when asked.
// Returns whether a body was added (a hole may leave out every sphere).
bool add_rough_rectangle(World& world, const Eigen::Vector3d& surface, const Eigen::Vector3d& n,
                         const Eigen::Vector3d& t1, const Eigen::Vector3d& t2, const Eigen::Vector2d& size,
                         double hole_radius, bool round_rim, double radius, double spacing,
                         std::uint16_t material) {
  const int n1 = static_cast<int>(std::floor(size.x() / spacing)) + 1;
  const int n2 = static_cast<int>(std::floor(size.y() / spacing)) + 1;
  std::vector<Eigen::Vector3d> offsets;
  for (int j = 0; j < n2; ++j) {
    for (int i = 0; i < n1; ++i) {
      const double a = (i - 0.5 * (n1 - 1)) * spacing, b = (j - 0.5 * (n2 - 1)) * spacing;
      if (hole_radius > 0 && std::hypot(a, b) < hole_radius + radius) continue;
      offsets.push_back(a * t1 + b * t2 - radius * n);
    }
  }
  if (round_rim) {
    const auto rim = round_hole_rim(t1, t2, n, hole_radius, radius);
    offsets.insert(offsets.end(), rim.begin(), rim.end());
  }
  if (offsets.empty()) return false;
  BodyDesc desc;
  desc.position = surface;
  desc.motion = MotionType::Static;
  add_body(world, desc, offsets, std::vector<double>(offsets.size(), radius), material);
  return true;
}

// In-plane axes for a plane normal; for a horizontal plane t1 = x and t2 = y.
std::pair<Eigen::Vector3d, Eigen::Vector3d> plane_axes(const Eigen::Vector3d& n) {
  const Eigen::Vector3d reference = std::abs(n.x()) > 0.9 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d t1 = (reference - reference.dot(n) * n).normalized();
  return {t1, n.cross(t1)};
}

void add_rough_cylinder(World& world, const Boundary& b) {
  const double ring = b.radius + b.particle_radius;  // m, particle centres: the inner surface is at b.radius
  const int around = static_cast<int>(std::ceil(2 * std::numbers::pi * ring / b.spacing));
  const int up = static_cast<int>(std::floor((b.z_max - b.z_min) / b.spacing)) + 1;
  const Eigen::Vector3d centre(b.axis.x(), b.axis.y(), b.z_min);
  std::vector<Eigen::Vector3d> offsets;
  for (int k = 0; k < up; ++k) {
    for (int i = 0; i < around; ++i) {
      const double angle = 2 * std::numbers::pi * (i + 0.5 * (k % 2)) / around;
      offsets.emplace_back(ring * std::cos(angle), ring * std::sin(angle), k * b.spacing);
    }
  }
  BodyDesc desc;
  desc.position = centre;
  desc.motion = MotionType::Static;
  add_body(world, desc, offsets, std::vector<double>(offsets.size(), b.particle_radius), b.material);
}

// The five faces of an open-topped box, inward normals.
struct Face {
  Eigen::Vector3d point, normal, t1, t2;
  Eigen::Vector2d size;
  const char* name;
};
std::vector<Face> box_faces(const Boundary& b) {
  const Eigen::Vector3d c = 0.5 * (b.min + b.max), e = b.max - b.min;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(), z = Eigen::Vector3d::UnitZ();
  const double zc = c.z();
  return {{{c.x(), c.y(), b.min.z()}, z, x, y, {e.x(), e.y()}, "floor (z = min)"},
          {{b.min.x(), c.y(), zc}, x, y, z, {e.y(), e.z()}, "x = min"},
          {{b.max.x(), c.y(), zc}, -x, y, z, {e.y(), e.z()}, "x = max"},
          {{c.x(), b.min.y(), zc}, y, x, z, {e.x(), e.z()}, "y = min"},
          {{c.x(), b.max.y(), zc}, -y, x, z, {e.x(), e.z()}, "y = max"}};
}

// Where the walls and bodies of add_boundary come from, kept apart so that the smooth walls can be
// listed as the world orders them (planes, then cylinders).
struct BoundaryNames {
  std::vector<std::string> planes, cylinders, bodies;
};

void add_boundary(World& world, const Boundary& b, BoundaryNames& names) {
  const std::string from = fmt::format("of [[boundary]] at line {}", b.line);
  switch (b.type) {
    case BoundaryType::Plane:
      if (b.rough) {
        const auto [t1, t2] = plane_axes(b.normal);
        if (add_rough_rectangle(world, b.point, b.normal, t1, t2, b.size, b.hole_radius, b.round_rim,
                                b.particle_radius, b.spacing, b.material)) {
          names.bodies.push_back("the rough plane " + from);
        }
      } else {
        world.walls.planes.push_back({b.point, b.normal, b.material});
        names.planes.push_back("the plane " + from);
      }
      break;
    case BoundaryType::Box:
      for (const Face& f : box_faces(b)) {
        const std::string face =
            fmt::format("the {} face of the {}box {}", f.name, b.rough ? "rough " : "", from);
        if (!b.rough) {
          world.walls.planes.push_back({f.point, f.normal, b.material});
          names.planes.push_back(face);
        } else if (add_rough_rectangle(world, f.point, f.normal, f.t1, f.t2, f.size, 0.0, false,
                                       b.particle_radius, b.spacing, b.material)) {
          names.bodies.push_back(face);
        }
      }
      break;
    case BoundaryType::Cylinder:
      if (b.rough) {
        add_rough_cylinder(world, b);
        names.bodies.push_back("the rough cylinder " + from);
      } else {
        world.walls.cylinders.push_back({b.axis, b.radius, b.z_min, b.z_max, b.material});
        names.cylinders.push_back("the cylinder " + from);
      }
      break;
  }
}

void add_prop(World& world, const Prop& p) {
  // A prop needs only the physical keys: hand-written bodies give no provenance or sampling quality.
  const body::ParticleBody body = body::read_body(p.body_file, body::BodyKeys::Physical);
  std::vector<Eigen::Vector3d> offsets;
  offsets.reserve(body.positions.size());
  for (const Eigen::Vector3f& x : body.positions) {
    offsets.push_back(Eigen::Vector3d(x.x(), x.y(), x.z()) - body.center_of_mass);
  }
  BodyDesc desc;
  desc.position = p.position + p.orientation * body.center_of_mass;
  desc.orientation = p.orientation;
  desc.linear_velocity = p.velocity;
  desc.angular_velocity = p.angular_velocity;
  desc.motion = p.motion;
  desc.inverse_mass = 1.0 / body.mass;
  desc.inverse_inertia = body.inertia.inverse();
  const std::uint32_t index =
      add_body(world, desc, offsets, std::vector<double>(offsets.size(), body.particle_radius), p.material);
  if (p.keyframes.empty()) return;
  // The track follows the centre of mass: each mesh-frame key moved to where it puts the centre.
  KinematicTrack track{index, p.keyframes};
  for (Keyframe& k : track.keys) k.position += k.orientation * body.center_of_mass;
  world.tracks.push_back(track);
  apply_tracks(world, 0.0);
}

// A breakable prop (issue 48): one dynamic solid sphere per particle of its `--fill` body, each with its
// share of the body's mass (sim::sphere_masses keeps the total and the centre of mass), moving with the
// prop's velocity and spin, and the bonds of its bond material between neighbours.
void add_breakable_prop(World& world, const Scene& scene, const Prop& p) {
  const body::ParticleBody body = body::read_body(p.body_file, body::BodyKeys::Physical);
  const std::size_t n = body.positions.size();
  std::vector<Eigen::Vector3d> mesh_centres;
  mesh_centres.reserve(n);
  for (const Eigen::Vector3f& x : body.positions) mesh_centres.emplace_back(x.x(), x.y(), x.z());
  const std::vector<double> radii(n, body.particle_radius);
  std::vector<bool> interior(n, false);
  for (std::size_t i = n - std::min(n, body.interior_count); i < n; ++i) interior[i] = true;
  std::vector<double> masses;
  try {
    masses = sphere_masses(mesh_centres, radii, interior, {body.mass, body.volume, body.center_of_mass});
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {} cannot be split into spheres: {} (resample it with `tetrasand sample "
                                 "--fill`)",
                                 where(scene, p.line, "prop.breakable"), p.body_file.string(), e.what()));
  }
  const BondMaterialSpec& spec = scene.bond_materials[static_cast<std::size_t>(p.bond_material)];
  const auto first = static_cast<std::uint32_t>(world.particles.size());
  const Eigen::Vector3d centre = p.position + p.orientation * body.center_of_mass;  // m, world
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x = p.position + p.orientation * mesh_centres[i];
    BodyDesc desc;
    desc.position = x;
    desc.orientation = p.orientation;
    desc.linear_velocity = p.velocity + p.angular_velocity.cross(x - centre);
    desc.angular_velocity = p.angular_velocity;
    desc.inverse_mass = 1.0 / masses[i];
    desc.inverse_inertia = Eigen::Matrix3d::Identity() / (0.4 * masses[i] * radii[i] * radii[i]);
    desc.motion = MotionType::Dynamic;
    add_body(world, desc, {Eigen::Vector3d::Zero()}, {radii[i]}, p.material);
  }
  append_bonds(world.bonds, build_bonds(mesh_centres, radii, spec.material, spec.seed), first,
               static_cast<std::uint16_t>(p.bond_material));
}

// bind_to: bonds of the bind material between the breakable prop's spheres (particles [layer,
// layer + layer_count)) and the particles of the prop it is bound to, closer than that material's
// bond_distance (r_a + r_b); pairs within either side are left out. Sphere order in each bond follows
// the world's (a < b), as the bond set's.
void bind_props(World& world, const BondMaterialSpec& spec, std::uint16_t material, std::uint32_t layer,
                std::uint32_t layer_count, std::uint32_t target, std::uint32_t target_count) {
  const std::vector<Eigen::Vector3d> positions = particle_positions(world);
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> radii;
  std::vector<std::uint32_t> particle;  // world index of each centre
  for (const auto& [start, count] : {std::pair{layer, layer_count}, std::pair{target, target_count}}) {
    for (std::uint32_t i = start; i < start + count; ++i) {
      centres.push_back(positions[i]);
      radii.push_back(world.particles.radius[i]);
      particle.push_back(i);
    }
  }
  const BondSet all = build_bonds(centres, radii, spec.material, spec.seed);
  BondSet& bonds = world.bonds;
  for (std::size_t k = 0; k < all.size(); ++k) {
    if ((all.a[k] < layer_count) == (all.b[k] < layer_count)) continue;  // both on one side
    const std::uint32_t a = particle[all.a[k]], b = particle[all.b[k]];
    bonds.a.push_back(std::min(a, b));
    bonds.b.push_back(std::max(a, b));
    bonds.material.push_back(material);
    bonds.tensile_strength.push_back(all.tensile_strength[k]);
    bonds.shear_strength.push_back(all.shear_strength[k]);
    bonds.intact.push_back(1);
    bonds.state.push_back(all.state[k]);
    bonds.rest_overlap.push_back(all.rest_overlap[k]);
  }
}

void add_grains(World& world, const Scene& scene, const std::vector<Eigen::Vector3d>& sites, const Emitter& e,
                std::mt19937_64& rng) {
  const std::vector<GrainDraw> draws = emitter_grain_draws(e);
  for (std::size_t i = 0; i < e.count; ++i) {
    const GrainDraw& d = draws[i];
    add_grain(world, scaled_grain(scene, d.type, d.scale), scene.grains[d.type].material, sites[i],
              random_orientation(rng), e.velocity);
  }
}

std::vector<Eigen::Vector3d> column_sites(const Emitter& e, double bound, std::mt19937_64& rng) {
  // Grow the column a layer at a time until it holds `count` grains.
  const double spacing = lattice_spacing(bound);
  const Eigen::Vector3d half(e.radius, e.radius, 0);
  for (double height = spacing;; height += spacing) {
    std::vector<Eigen::Vector3d> sites = grain_sites_in_box(e.centre - half, e.centre + half + Eigen::Vector3d(0, 0, height),
                                                            bound, rng);
    std::erase_if(sites, [&](const Eigen::Vector3d& s) { return (s - e.centre).head<2>().norm() > e.radius - bound; });
    if (sites.size() >= e.count) return sites;
    if (height > 1e6 * spacing) return sites;  // the radius holds no grain at all
  }
}

// The bond materials go into the world in scene order (BondSet::material indexes both), and each
// bind_to prop's binding bonds after every prop's own.
void add_bonds_between_props(World& world, const Scene& scene, const std::vector<std::uint32_t>& prop_bodies) {
  if (!scene.has_bonds()) return;
  for (const BondMaterialSpec& spec : scene.bond_materials) world.bond_materials.push_back(spec.material);
  for (std::size_t i = 0; i < scene.props.size(); ++i) {
    const Prop& p = scene.props[i];
    if (p.bind_to < 0) continue;
    const auto t = static_cast<std::size_t>(p.bind_to);
    const auto particles_of = [&](std::size_t k) {
      const std::uint32_t first = world.bodies.first_particle[prop_bodies[k]];
      const std::uint32_t last_body = prop_bodies[k] + static_cast<std::uint32_t>(prop_body_count(scene.props[k])) - 1;
      return std::pair{first, world.bodies.first_particle[last_body] + world.bodies.particle_count[last_body] - first};
    };
    const auto [layer, layer_count] = particles_of(i);
    const auto [target, target_count] = particles_of(t);
    bind_props(world, scene.bond_materials[static_cast<std::size_t>(p.bind_material)],
               static_cast<std::uint16_t>(p.bind_material), layer, layer_count, target, target_count);
  }
}

}  // namespace


std::vector<Eigen::Vector3d> round_hole_rim(const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                                            const Eigen::Vector3d& n, double hole_radius, double radius) {
  const double circle = hole_radius + radius;
  // Neighbours at most one radius apart along the circle: the gap between two spheres reaches at most
  // radius (1 - cos 30 deg) = 0.134 radius beyond their inner edges, and no grain sphere fits through.
  const int count = std::max(3, static_cast<int>(std::ceil(2 * std::numbers::pi * circle / radius)));
  std::vector<Eigen::Vector3d> rim;
  rim.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double angle = 2 * std::numbers::pi * i / count;
    rim.push_back(circle * (std::cos(angle) * t1 + std::sin(angle) * t2) - radius * n);
  }
  return rim;
}

World make_world(const Scene& scene, WorldSources* sources) {
  check_scene_sizes(scene);
  World world;
  world.materials = scene.materials;
  world.gravity = scene.gravity;
  BoundaryNames names;
  for (const Boundary& b : scene.boundaries) add_boundary(world, b, names);
  std::vector<std::uint32_t> prop_bodies;
  for (const Prop& p : scene.props) {
    prop_bodies.push_back(static_cast<std::uint32_t>(world.bodies.size()));
    const std::string prop =
        fmt::format("the prop of [[prop]] at line {} ({})", p.line, p.body_file.filename().string());
    if (!p.breakable) {
      add_prop(world, p);
      names.bodies.push_back(prop);
      continue;
    }
    add_breakable_prop(world, scene, p);
    for (std::size_t i = 0; i < p.spheres; ++i) names.bodies.push_back(fmt::format("sphere {} of {}", i, prop));
  }
  add_bonds_between_props(world, scene, prop_bodies);
  check_world_sizes(scene, world, prop_bodies);
  if (sources) {
    sources->smooth_walls = names.planes;
    sources->smooth_walls.insert(sources->smooth_walls.end(), names.cylinders.begin(), names.cylinders.end());
    sources->bodies = names.bodies;
    sources->prop_bodies = prop_bodies;
  }
  for (const Emitter& e : scene.emitters) {
    if (e.type == EmitterType::Pour) continue;
    std::mt19937_64 rng(e.seed);
    const double bound = emitter_bound(scene, e);  // m: the lattice is spaced for the largest grain
    const std::vector<Eigen::Vector3d> sites = e.type == EmitterType::Fill
                                                   ? grain_sites_in_box(e.min, e.max, bound, rng)
                                                   : column_sites(e, bound, rng);
    if (sites.size() < e.count) {
      throw InputError(
          fmt::format("{}: the region holds only {} grains without overlap (spacing {:.3g} m = 2.2 "
                      "bounding radii of the largest grain), count = {}",
                      where(scene, e.line, "emitter.count"), sites.size(), lattice_spacing(bound), e.count));
    }
    add_grains(world, scene, sites, e, rng);
  }
  return world;
}

PourEmitter::PourEmitter(const Scene& scene, const Emitter& emitter)
    : types_(scene.grains),
      draws_(emitter_grain_draws(emitter)),
      bound_(emitter_bound(scene, emitter)),
      emitter_(emitter),
      rng_(emitter.seed) {
  for (const GrainSpec& g : types_) densities_.push_back(scene.materials[g.material].density);
  sites_ = grain_sites_in_box(emitter.min, emitter.max, bound_, rng_);
  if (sites_.empty()) {
    throw InputError(fmt::format("{}: the region is smaller than one grain (bounding diameter {:.3g} m)",
                                 where(scene, emitter.line, "emitter.max"), 2 * bound_));
  }
}

PourProgress PourEmitter::progress() const {
  std::ostringstream rng;
  rng << rng_;
  return {next_site_, emitted_, rng.str()};
}

void PourEmitter::restore(const PourProgress& progress) {
  if (progress.next_site >= sites_.size() || progress.emitted > emitter_.count) {
    throw InputError(
        fmt::format("a pour emitter at site {} of {} with {} of {} grains released does not match the "
                    "scene's",
                    progress.next_site, sites_.size(), progress.emitted, emitter_.count));
  }
  next_site_ = static_cast<std::size_t>(progress.next_site);
  emitted_ = static_cast<std::size_t>(progress.emitted);
  std::istringstream rng(progress.rng);
  std::mt19937_64 restored;
  if (!(rng >> restored)) throw InputError("a pour emitter's random generator state is damaged");
  rng_ = restored;
}

std::size_t PourEmitter::emit(World& world) {
  if (finished() || world.time < emitter_.start) return 0;
  const double released = std::floor((world.time - emitter_.start) * emitter_.rate) + 1;
  const std::size_t due = std::min(emitter_.count, static_cast<std::size_t>(released));
  std::size_t added = 0;
  for (std::size_t tries = 0; emitted_ < due && tries < sites_.size(); ++tries) {
    const Eigen::Vector3d& site = sites_[next_site_];
    next_site_ = (next_site_ + 1) % sites_.size();
    const GrainDraw& d = draws_[emitted_];
    const GrainSpec& type = types_[d.type];
    const GrainShape grain =
        make_tetrahedral_grain(d.scale * type.radius, d.scale * type.edge, densities_[d.type]);
    bool free = true;
    for (std::size_t b = 0; b < world.bodies.size() && free; ++b) {
      if (world.bodies.motion[b] != MotionType::Dynamic) continue;
      const double clearance = (grain.bounding_radius + world.bodies.bounding_radius[b]) * 1.02;  // m
      free = (world.bodies.position[b] - site).norm() >= clearance;
    }
    if (!free) continue;
    add_grain(world, grain, type.material, site, random_orientation(rng_), emitter_.velocity);
    ++emitted_;
    ++added;
  }
  return added;
}

std::size_t fixture_bodies(const Scene& scene, const World& world) {
  std::size_t fixtures = 0;
  for (MotionType m : world.bodies.motion) fixtures += m != MotionType::Dynamic ? 1 : 0;
  for (const Prop& p : scene.props) fixtures += p.motion == MotionType::Dynamic ? prop_body_count(p) : 0;
  return std::min(fixtures, world.bodies.size());
}

std::vector<BodyRange> prop_body_ranges(const Scene& scene, const World& world) {
  std::size_t total = 0;
  for (const Prop& p : scene.props) total += prop_body_count(p);
  std::size_t next = fixture_bodies(scene, world) - std::min(total, fixture_bodies(scene, world));
  std::vector<BodyRange> ranges;
  for (const Prop& p : scene.props) {
    ranges.push_back({static_cast<std::uint32_t>(next), static_cast<std::uint32_t>(prop_body_count(p)), p.breakable});
    next += prop_body_count(p);
  }
  return ranges;
}

namespace {

const BodyRange* breakable_range_of(const std::vector<BodyRange>& ranges, std::size_t body) {
  for (const BodyRange& r : ranges) {
    if (r.breakable && body >= r.first && body < r.first + r.count) return &r;
  }
  return nullptr;
}

// 1/kg of a breakable prop's lightest sphere: the shortest contact it takes part in.
double largest_inverse_mass(const World& world, const BodyRange& range) {
  double inverse = 0;
  for (std::uint32_t b = range.first; b < range.first + range.count; ++b)
    inverse = std::max(inverse, world.bodies.inverse_mass[b]);
  return inverse;
}

// The contacts of a breakable prop's spheres once their bonds break: sphere on sphere (fragments
// meeting) and sphere on each boundary, for its lightest sphere (solid sphere: a push at the contact
// point has 1/m_t = 1/m + r^2 / (2/5 m r^2) = 3.5/m).
void add_breakable_cases(const Scene& scene, const World& world, const std::vector<BodyRange>& ranges,
                         std::vector<SceneContactCase>& cases) {
  for (std::size_t i = 0; i < scene.props.size(); ++i) {
    if (!ranges[i].breakable || ranges[i].count == 0) continue;
    const Prop& p = scene.props[i];
    const double m = 1 / largest_inverse_mass(world, ranges[i]);
    const double r = world.particles.radius[world.bodies.first_particle[ranges[i].first]];
    const std::string who = fmt::format("a sphere of the breakable prop \"{}\"", p.name);
    const PairCoefficients self = make_pair_coefficients(scene.materials[p.material], scene.materials[p.material],
                                                         scene.simulation.step.normal_damping);
    cases.push_back({{m / 2, r / 2, self.effective_modulus, m / 7, self.tangential_damping}, r, m, who,
                     "another of its spheres"});
    for (const Boundary& b : scene.boundaries) {
      const PairCoefficients c = make_pair_coefficients(scene.materials[p.material], scene.materials[b.material],
                                                        scene.simulation.step.normal_damping);
      const double radius = b.rough ? r * b.particle_radius / (r + b.particle_radius) : r;
      cases.push_back({{m, radius, c.effective_modulus, m / 3.5, c.tangential_damping},
                       b.rough ? std::min(r, b.particle_radius) : r,
                       m,
                       who,
                       fmt::format("the {}boundary at line {}", b.rough ? "rough " : "", b.line)});
    }
  }
}

}  // namespace

std::vector<SceneContactCase> scene_contact_cases(const Scene& scene, const World& world,
                                                  const WorldSources* sources) {
  const std::vector<GrainKind> kinds = scene_grain_kinds(scene);
  const bool one_kind = kinds.size() == 1;
  auto pair = [&](std::uint16_t a, std::uint16_t b) {
    return make_pair_coefficients(scene.materials[a], scene.materials[b],
                                  scene.simulation.step.normal_damping);
  };
  std::vector<SceneContactCase> cases;
  const std::vector<BodyRange> ranges = prop_body_ranges(scene, world);
  add_breakable_cases(scene, world, ranges, cases);
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    const GrainShape& g = kinds[i].shape;
    const std::uint16_t sand = scene.grains[kinds[i].type].material;
    const std::string grain = one_kind ? "a grain" : kinds[i].name;
    const double inverse_tangential = grain_tangential_inverse_mass(g);  // 1/kg
    const double r = g.particle_radius;
    for (std::size_t j = i; j < kinds.size(); ++j) {  // grain against grain, each pair of kinds once
      const GrainShape& h = kinds[j].shape;
      const PairCoefficients c = pair(sand, scene.grains[kinds[j].type].material);
      const double rh = h.particle_radius;
      // A kind against itself as m/2, r/2 exactly: the step of a one-kind scene is the one it always had.
      const double m_eff = i == j ? g.mass / 2 : g.mass * h.mass / (g.mass + h.mass);
      const double r_eff = i == j ? r / 2 : r * rh / (r + rh);
      cases.push_back({{m_eff, r_eff, c.effective_modulus,
                        i == j ? 1 / (2 * inverse_tangential)
                               : 1 / (inverse_tangential + grain_tangential_inverse_mass(h)),
                        c.tangential_damping},
                       std::min(r, rh),
                       std::max(g.mass, h.mass),
                       grain,
                       one_kind ? "another grain" : kinds[j].name});
    }
    for (const Boundary& b : scene.boundaries) {
      const PairCoefficients c = pair(sand, b.material);
      const double radius = b.rough ? r * b.particle_radius / (r + b.particle_radius) : r;
      cases.push_back({{g.mass, radius, c.effective_modulus, 1 / inverse_tangential, c.tangential_damping},
                       b.rough ? std::min(r, b.particle_radius) : r,
                       g.mass,
                       grain,
                       fmt::format("the {}boundary at line {}", b.rough ? "rough " : "", b.line)});
    }
    for (std::size_t k = 0; k < fixture_bodies(scene, world); ++k) {
      // A breakable prop's spheres are alike but for their mass: one case, its lightest sphere's.
      const BodyRange* breakable = breakable_range_of(ranges, k);
      if (breakable && k != breakable->first) continue;
      const std::uint32_t first = world.bodies.first_particle[k];
      const PairCoefficients c = pair(sand, world.particles.material[first]);
      const double rp = world.particles.radius[first];
      const double inverse_mass = breakable ? largest_inverse_mass(world, *breakable) : world.bodies.inverse_mass[k];
      const bool named = sources && k < sources->bodies.size();
      cases.push_back({{1 / (1 / g.mass + inverse_mass), r * rp / (r + rp), c.effective_modulus,
                        1 / inverse_tangential, c.tangential_damping},
                       std::min(r, rp),
                       g.mass,
                       grain,
                       named ? sources->bodies[k] : fmt::format("body {}", k)});
    }
  }
  return cases;
}

DesignSpeed scene_design_speed(const Scene& scene, const World& world) {
  if (scene.simulation.max_impact_speed > 0)
    return {scene.simulation.max_impact_speed, "simulation.max_impact_speed", 0};
  // Free fall over the scene's height, plus the fastest launched grain or moving prop.
  double z_min = 0, z_max = 0;
  bool first = true;
  for (const Eigen::Vector3d& x : particle_positions(world)) {
    z_min = first ? x.z() : std::min(z_min, x.z());
    z_max = first ? x.z() : std::max(z_max, x.z());
    first = false;
  }
  for (const Boundary& b : scene.boundaries) {
    const double z = b.type == BoundaryType::Plane ? b.point.z()
                     : b.type == BoundaryType::Box ? b.min.z()
                                                   : b.z_min;
    z_min = first ? z : std::min(z_min, z);
    z_max = first ? z : std::max(z_max, z);
    first = false;
  }
  DesignSpeed launch{0, "gravity", 0};  // the fastest launch, and where it is set
  auto faster = [&](double speed, std::string key, int line) {
    if (speed > launch.speed) launch = {speed, std::move(key), line};
  };
  for (const Emitter& e : scene.emitters) {
    z_max = std::max(z_max, e.type == EmitterType::Column ? e.centre.z() : e.max.z());
    faster(e.velocity.norm(), "emitter.velocity", e.line);
  }
  for (const Prop& p : scene.props) {
    faster(p.velocity.norm(), "prop.velocity", p.line);
    if (p.servo) faster(p.servo->max_speed, "prop.servo.max_speed", p.line);
    for (std::size_t k = 1; k < p.keyframes.size(); ++k) {  // keyframed: its fastest segment
      const double span = p.keyframes[k].time - p.keyframes[k - 1].time;
      faster((p.keyframes[k].position - p.keyframes[k - 1].position).norm() / span, "prop.keyframes", p.line);
    }
  }
  const double launched = launch.speed;                                       // m/s
  const double fall = std::sqrt(2 * scene.gravity.norm() * (z_max - z_min));  // m/s
  const double speed = std::max(0.5, fall + launched);
  return fall >= launched ? DesignSpeed{speed, "gravity", 0} : DesignSpeed{speed, launch.key, launch.line};
}

std::vector<ParticleKind> scene_particle_kinds(const Scene& scene) {
  std::vector<ParticleKind> kinds;
  for (const GrainKind& k : scene_grain_kinds(scene))
    kinds.push_back({k.shape.particle_radius, scene.materials[scene.grains[k.type].material]});
  for (const Boundary& b : scene.boundaries) {
    if (b.rough) kinds.push_back({b.particle_radius, scene.materials[b.material]});
  }
  return kinds;
}

BondStepBound scene_bond_time_step(const World& world) {
  BondStepBound bound;
  if (world.bonds.size() == 0) return bound;
  std::vector<double> masses(world.particles.size()), radii = world.particles.radius;
  for (std::size_t i = 0; i < masses.size(); ++i) masses[i] = 1.0 / world.bodies.inverse_mass[world.particles.body[i]];
  // One material at a time (sim::bond_time_step takes one): the bonds of each, then the shortest.
  for (std::size_t m = 0; m < world.bond_materials.size(); ++m) {
    BondSet of_material;
    for (std::size_t k = 0; k < world.bonds.size(); ++k) {
      if (world.bonds.material[k] != m) continue;
      of_material.a.push_back(world.bonds.a[k]);
      of_material.b.push_back(world.bonds.b[k]);
    }
    const double step = bond_time_step(of_material, masses, radii, world.bond_materials[m]);
    if (step < bound.step) bound = {step, static_cast<int>(m)};
  }
  return bound;
}

TimeStepBound scene_time_step_bound(const Scene& scene, const World& world, double impact_speed) {
  std::vector<ContactCase> cases;
  for (const SceneContactCase& c : scene_contact_cases(scene, world)) cases.push_back(c.contact);
  const double speed = impact_speed > 0 ? impact_speed : scene_design_speed(scene, world).speed;
  TimeStepBound bound = time_step_bound(cases, scene_particle_kinds(scene), speed);
  const BondStepBound bonds = scene_bond_time_step(world);
  if (bonds.material >= 0 && !(bonds.step >= kShortestBondTimeStep)) {
    const BondMaterialSpec& spec = scene.bond_materials[static_cast<std::size_t>(bonds.material)];
    throw InputError(fmt::format(
        "{}: the bonds of this material need a time step of {:.3g} s, below the {:g} s a run can take (a run "
        "of a second would take over a billion steps): lower E, or use larger spheres (resample with a larger "
        "--radius)",
        scene_location(scene, "bond_material.E", spec.line), bonds.step, kShortestBondTimeStep));
  }
  add_bond_bound(bound, bonds.step);
  return bound;
}

}  // namespace ts::scene
