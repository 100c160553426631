// `tetrasand export lammps`: the scene as a LAMMPS deck (see export_lammps.h for the mapping).
#include "export/lammps_deck.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/checked_values.h"
#include "core/error.h"
#include "scene/grain_mix.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "sim/grain.h"

namespace ts::exporter {
namespace {

namespace fs = std::filesystem;

// A number the deck would hold that is not finite: LAMMPS cannot read `inf` or `-nan` back, and
// `sim` refuses the same values. Thrown by num() while a file's text is built; write_deck() turns
// it into a refusal naming the file, before anything is written.
class NonFiniteNumber : public std::runtime_error {
 public:
  explicit NonFiniteNumber(double value) : std::runtime_error(finite_problem(value)), value_(value) {}
  double value() const { return value_; }

 private:
  double value_;
};

// Round-trip precision for every number LAMMPS reads back; every one passes the value checker.
std::string num(double v) {
  if (!finite_problem(v).empty()) throw NonFiniteNumber(v);
  return fmt::format("{:.17g}", v);
}
std::string vec(const Eigen::Vector3d& v) { return fmt::format("{} {} {}", num(v.x()), num(v.y()), num(v.z())); }

[[noreturn]] void refuse(const Scene& scene, const std::string& what) {
  throw InputError(scene.file, "cannot export to LAMMPS: " + what);
}

// The grain-contact reference used to turn tetrasand's constant tangential damping gamma_s (N s/m)
// into LAMMPS's linear_nohistory x_gamma_t, which scales with the normal damping
// eta_n = alpha sqrt(m* k_n a), a = sqrt(R* delta): LAMMPS's eta_t equals gamma_s at the overlap of
// one grain resting on another under gravity (eta_n grows only as delta^(1/4) away from it).
struct ReferenceContact {
  double effective_mass;    // kg
  double effective_radius;  // m
  double weight;            // N, the load pressing the contact at rest
};

// Atom types: one per material (grains, walls, static and kinematic props), plus one per dynamic
// prop, so that its contacts get coefficients matched at its own mass (LAMMPS's tangential damping
// grows with sqrt(m*)). `mass` and `radius` describe the body a contact of this type belongs to.
struct AtomType {
  std::uint16_t material;
  double mass;    // kg
  double radius;  // m
};

struct PairModel {
  double lammps_modulus = 0;      // E handed to hertz/material (Pa), with nu = 0
  double lammps_restitution = 0;  // e whose Tsuji alpha equals tetrasand's damping strength
  double friction = 0;
  double tangential_factor = 0;   // x_gamma_t of linear_nohistory / mindlin
  double tangential_stiffness = 0;  // Pa: 8 G* for mindlin (tetrasand's spring model), 0 = no spring
  double reference_overlap = 0;   // m, where eta_t == gamma_s
};

PairModel pair_model(const Scene& scene, const Material& a, const Material& b, const ReferenceContact& ref) {
  const PairCoefficients p = make_pair_coefficients(a, b, NormalDamping::Tsuji);
  PairModel m;
  m.lammps_modulus = 2.0 * p.effective_modulus;  // E/(2 (1 - 0^2)) = E*
  m.friction = p.friction;
  if (p.damping_strength <= 0 && p.tangential_damping > 0) {
    refuse(scene, "restitution 1 with viscous tangential damping (LAMMPS ties tangential damping to normal damping)");
  }
  m.lammps_restitution = lammps_restitution_for_alpha(p.damping_strength);
  const double k_n = 4.0 / 3.0 * p.effective_modulus * std::sqrt(ref.effective_radius);  // N/m^1.5
  m.reference_overlap = std::pow(ref.weight / k_n, 2.0 / 3.0);
  const double knfac = k_n * std::sqrt(m.reference_overlap);  // N/m
  const double eta_n = p.damping_strength * std::sqrt(ref.effective_mass * knfac);  // N s/m
  m.tangential_factor = eta_n > 0 ? p.tangential_damping / eta_n : 0.0;
  if (scene.simulation.step.tangential == TangentialModel::Spring) {
    m.tangential_stiffness = 8.0 * p.effective_shear_modulus;  // k_t = 8 G* sqrt(R* delta), as LAMMPS's mindlin
  }
  return m;
}

std::string granular_model(const PairModel& m) {
  const std::string tangential =
      m.tangential_stiffness > 0
          ? fmt::format("mindlin {} {} {}", num(m.tangential_stiffness), num(m.tangential_factor), num(m.friction))
          : fmt::format("linear_nohistory {} {}", num(m.tangential_factor), num(m.friction));
  return fmt::format("hertz/material {} {} 0.0 tangential {} damping tsuji limit_damping", num(m.lammps_modulus),
                     num(m.lammps_restitution), tangential);
}

bool is_dynamic(const World& w, std::size_t b) { return w.bodies.motion[b] == MotionType::Dynamic; }

// A dynamic body of one particle: LAMMPS integrates it as a plain sphere (fix rigid/small refuses
// one-atom bodies).
bool is_free_sphere(const World& w, std::size_t b) { return is_dynamic(w, b) && w.bodies.particle_count[b] == 1; }

// Molecule IDs: rigid dynamic bodies 1..R, free spheres R+1..D, each in world order, then the
// static and kinematic ones, so each group is one range of molecule IDs.
std::vector<std::int64_t> molecule_ids(const World& w, std::size_t* rigid_count, std::size_t* dynamic_count) {
  std::vector<std::int64_t> ids(w.bodies.size());
  std::int64_t next = 1;
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (is_dynamic(w, b) && !is_free_sphere(w, b)) ids[b] = next++;
  }
  *rigid_count = static_cast<std::size_t>(next - 1);
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (is_free_sphere(w, b)) ids[b] = next++;
  }
  *dynamic_count = static_cast<std::size_t>(next - 1);
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (!is_dynamic(w, b)) ids[b] = next++;
  }
  return ids;
}

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
  void add(const Eigen::Vector3d& p, double r) {
    const Eigen::Vector3d reach = Eigen::Vector3d::Constant(r);
    lo = lo.cwiseMin(p - reach);
    hi = hi.cwiseMax(p + reach);
  }
};

std::string data_file(const World& w, const std::vector<std::int64_t>& mol, const std::vector<int>& body_type,
                      std::size_t type_count, const Box& box, bool velocities) {
  const std::vector<Eigen::Vector3d> x = particle_positions(w);
  std::string out = "LAMMPS data file written by tetrasand export lammps (SI units: m, kg)\n\n";
  out += fmt::format("{} atoms\n{} atom types\n\n", x.size(), type_count);
  out += fmt::format("{} {} xlo xhi\n{} {} ylo yhi\n{} {} zlo zhi\n\n", num(box.lo.x()), num(box.hi.x()),
                     num(box.lo.y()), num(box.hi.y()), num(box.lo.z()), num(box.hi.z()));
  // fix gravity pulls on atom masses: a dynamic body's atom densities are scaled so that its atoms
  // weigh the body's mass (grains: already so, four full spheres; sampled props overlap).
  std::vector<double> density_scale(w.bodies.size(), 1.0);
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (!is_dynamic(w, b)) continue;
    double atoms = 0;  // kg
    for (std::uint32_t k = 0; k < w.bodies.particle_count[b]; ++k) {
      const std::uint32_t i = w.bodies.first_particle[b] + k;
      atoms += w.materials[w.particles.material[i]].density * 4.0 / 3.0 * std::numbers::pi *
               std::pow(w.particles.radius[i], 3);
    }
    density_scale[b] = 1.0 / (w.bodies.inverse_mass[b] * atoms);
  }
  out += "Atoms # sphere: id type diameter density x y z\n\n";
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::uint16_t m = w.particles.material[i];
    const double density = w.materials[m].density * density_scale[w.particles.body[i]];  // kg/m^3
    const int type = body_type[w.particles.body[i]] > 0 ? body_type[w.particles.body[i]] : m + 1;
    out += fmt::format("{} {} {} {} {}\n", i + 1, type, num(2 * w.particles.radius[i]), num(density), vec(x[i]));
  }
  if (velocities) {
    // Each atom moves with its body (fix rigid/small recomputes its rigid bodies' atoms from
    // bodies.rigid; plain spheres keep these). Before Molecules: placed after that fix
    // section, LAMMPS 29 Sep 2021 took the first velocity row for a section name.
    out += "\nVelocities\n\n";
    for (std::size_t i = 0; i < x.size(); ++i) {
      const std::uint32_t b = w.particles.body[i];
      const Eigen::Vector3d& omega = w.bodies.angular_velocity[b];
      const Eigen::Vector3d v = w.bodies.linear_velocity[b] + omega.cross(x[i] - w.bodies.position[b]);
      out += fmt::format("{} {} {}\n", i + 1, vec(v), vec(omega));
    }
  }
  out += "\nMolecules\n\n";
  for (std::size_t i = 0; i < x.size(); ++i) out += fmt::format("{} {}\n", i + 1, mol[w.particles.body[i]]);
  return out;
}

// fix rigid/small infile: ID masstotal xcm ycm zcm ixx iyy izz ixy ixz iyz vxcm vycm vzcm lx ly lz
// ixcm iycm izcm, inertia about the centre of mass in the world frame, angular momentum L = I w.
std::string bodies_file(const World& w, const std::vector<std::int64_t>& mol, std::size_t rigid_count) {
  std::string out = "# tetrasand export lammps: explicit mass (kg), centre of mass (m), world-frame inertia (kg m^2)\n";
  out += "# ID masstotal xcm ycm zcm ixx iyy izz ixy ixz iyz vxcm vycm vzcm lx ly lz ixcm iycm izcm\n";
  out += fmt::format("{}\n", rigid_count);
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (!is_dynamic(w, b) || is_free_sphere(w, b)) continue;
    const Eigen::Matrix3d r = w.bodies.orientation[b].toRotationMatrix();
    const Eigen::Matrix3d inertia = r * w.bodies.inverse_inertia[b].inverse() * r.transpose();
    const Eigen::Vector3d momentum = inertia * w.bodies.angular_velocity[b];
    out += fmt::format("{} {} {} {} {} {} {} {} {} {} {} 0 0 0\n", mol[b], num(1.0 / w.bodies.inverse_mass[b]),
                       vec(w.bodies.position[b]), num(inertia(0, 0)), num(inertia(1, 1)), num(inertia(2, 2)),
                       num(inertia(0, 1)), num(inertia(0, 2)), num(inertia(1, 2)), vec(w.bodies.linear_velocity[b]),
                       vec(momentum));
  }
  return out;
}

std::string molecule_file(const GrainShape& g, std::uint16_t material) {
  std::string out = "# tetrasand grain: four spheres on a regular tetrahedron (SI), explicit mass, COM, inertia\n\n";
  const double sphere_mass = g.mass / 4;
  out += fmt::format("4 atoms\n{} mass\n0 0 0 com\n{} {} {} 0 0 0 inertia\n\nCoords\n\n", num(g.mass), num(g.inertia),
                     num(g.inertia), num(g.inertia));
  for (int i = 0; i < 4; ++i) out += fmt::format("{} {}\n", i + 1, vec(g.offsets[i]));
  out += "\nTypes\n\n";
  for (int i = 0; i < 4; ++i) out += fmt::format("{} {}\n", i + 1, material + 1);
  out += "\nDiameters\n\n";
  for (int i = 0; i < 4; ++i) out += fmt::format("{} {}\n", i + 1, num(2 * g.particle_radius));
  out += "\nMasses\n\n";
  for (int i = 0; i < 4; ++i) out += fmt::format("{} {}\n", i + 1, num(sphere_mass));
  return out;
}

bool axis_aligned(const Eigen::Vector3d& n, int* axis) {
  for (int k = 0; k < 3; ++k) {
    if (std::abs(std::abs(n[k]) - 1.0) < 1e-12) {
      *axis = k;
      return true;
    }
  }
  return false;
}

void check_exportable(const Scene& scene, const World& w) {
  const StepSettings& s = scene.simulation.step;
  if (s.normal_damping != NormalDamping::Tsuji) {
    refuse(scene, "simulation.normal_damping = \"thesis\" has no LAMMPS equivalent (use \"tsuji\")");
  }
  if (s.angular_damping_rate > 0) refuse(scene, "simulation.angular_damping_rate has no LAMMPS equivalent");
  if (scene.has_bonds()) {
    refuse(scene, "a breakable prop (its bonds would need LAMMPS' BPM package, which Debian's LAMMPS is built "
                  "without; run the scene with tetrasand sim --backend cpu)");
  }
  if (!w.tracks.empty()) {
    refuse(scene, "a keyframed kinematic prop (this export writes LAMMPS fix move linear/rotate, not a path)");
  }
  if (std::any_of(scene.props.begin(), scene.props.end(),
                  [](const Prop& p) { return p.servo.has_value(); })) {
    refuse(scene,
           "a prop with [prop.servo] (LAMMPS would need fix wall/servo or a fix rigid with a force target)");
  }
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (w.bodies.motion[b] != MotionType::Kinematic) continue;
    if (w.bodies.linear_velocity[b].norm() > 0 && w.bodies.angular_velocity[b].norm() > 0) {
      refuse(scene, "a kinematic prop that both translates and spins (LAMMPS fix move does one or the other)");
    }
  }
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (!is_free_sphere(w, b)) continue;
    const std::uint32_t i = w.bodies.first_particle[b];
    const double r = w.particles.radius[i];
    const Eigen::Matrix3d solid = Eigen::Matrix3d::Identity() * w.bodies.inverse_mass[b] / (0.4 * r * r);
    if (w.particles.offset[i].norm() > 1e-9 * r || !w.bodies.inverse_inertia[b].isApprox(solid, 1e-9)) {
      refuse(scene, fmt::format("dynamic body {} is one particle off its centre of mass or with other than a solid "
                                "sphere's inertia (LAMMPS's fix rigid/small refuses one-atom bodies, and fix "
                                "nve/sphere integrates a centred solid sphere)", b));
    }
  }
  const bool pours = std::any_of(scene.emitters.begin(), scene.emitters.end(),
                                 [](const Emitter& e) { return e.type == EmitterType::Pour; });
  const bool dynamic_props = std::any_of(scene.props.begin(), scene.props.end(),
                                         [](const Prop& p) { return p.motion == MotionType::Dynamic; });
  if (pours && dynamic_props) {
    refuse(scene, "pour emitters together with dynamic props (fix deposit cannot add grains to the per-type wall "
                  "groups the props need)");
  }
}

struct PourEvent {
  std::int64_t step;
  const Emitter* emitter;
  std::vector<double> molfrac;  // share of each molecule template (DeckPlan::templates)
};

// A molecule template for fix deposit: a grain type at one scale (a sieve class, or the mass-mean
// scale of one equal-count size bin of a uniform or lognormal distribution).
struct GrainTemplate {
  std::uint16_t type;
  double scale;
};

// Continuous size distributions of pour emitters become this many equal-count bins per grain type.
constexpr std::size_t kSizeBins = 5;

// Everything the deck's sections are written from: the initial world, the grain, the molecule and
// atom type of every body, the simulation box, the run's length and the pour events in time order.
struct DeckPlan {
  DeckPlan(const Scene& s, World w) : scene(s), world(std::move(w)), kinds(scene_grain_kinds(s)) {}
  const Scene& scene;
  World world;
  std::vector<GrainKind> kinds;  // the smallest and largest grain of each type
  std::vector<GrainTemplate> templates;
  double dt = 0;  // s
  std::int64_t steps = 0;
  std::vector<std::int64_t> mol;  // molecule id per body
  // Molecules 1..rigid_count are rigid bodies, rigid_count+1..dynamic_count free spheres.
  std::size_t rigid_count = 0, dynamic_count = 0, frozen_particles = 0;
  const LammpsStateRun* state = nullptr;  // set when the deck continues a state (export_lammps_state)
  // Bodies 0..fixtures-1 are the scene's props and rough walls, as make_world lays them out; a state
  // may append static bodies after the grains (a silo's rim), which are not props.
  std::size_t fixtures = 0;
  double max_radius = 0, max_body_extent = 0;  // m
  Box box;
  std::vector<PourEvent> pours;
  // Atom types: materials first (type = material + 1), then one per dynamic prop.
  std::vector<AtomType> types;
  std::vector<int> body_type;  // per body; 0: its material's type
  std::set<int> dynamic_types;
  double g_ref = 0;  // m/s^2, for the reference overlaps

  ReferenceContact type_pair(std::size_t a, std::size_t b) const {
    const AtomType &ta = types[a], &tb = types[b];
    return ReferenceContact{ta.mass * tb.mass / (ta.mass + tb.mass), ta.radius * tb.radius / (ta.radius + tb.radius),
                            std::min(ta.mass, tb.mass) * g_ref};
  }
  ReferenceContact type_wall(int t) const {
    const AtomType& ta = types[static_cast<std::size_t>(t - 1)];
    return ReferenceContact{ta.mass, ta.radius, ta.mass * g_ref};
  }
  std::string material_name(std::uint16_t m) const {
    return scene.material_names.size() > m ? scene.material_names[m] : std::to_string(m);
  }
  // The contact model of a dynamic atom type against a wall of `wall_material`.
  std::string wall_model(int type, std::uint16_t wall_material) const {
    return granular_model(pair_model(scene, world.materials[types[static_cast<std::size_t>(type - 1)].material],
                                     world.materials[wall_material], type_wall(type)));
  }
  double skin() const { return 0.3 * 2 * max_radius; }  // m
};

// The box around every particle and pour region, the largest radius and body, the frozen count.
void plan_geometry(DeckPlan& plan) {
  const World& w = plan.world;
  for (const GrainKind& k : plan.kinds) {
    plan.max_radius = std::max(plan.max_radius, k.shape.particle_radius);
    plan.max_body_extent = std::max(plan.max_body_extent, 2 * k.shape.bounding_radius);
  }
  const std::vector<Eigen::Vector3d> x = particle_positions(w);
  for (std::size_t i = 0; i < x.size(); ++i) {
    plan.box.add(x[i], w.particles.radius[i]);
    plan.max_radius = std::max(plan.max_radius, w.particles.radius[i]);
    if (!is_dynamic(w, w.particles.body[i])) ++plan.frozen_particles;
  }
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (is_dynamic(w, b)) plan.max_body_extent = std::max(plan.max_body_extent, 2 * w.bodies.bounding_radius[b]);
  }
}

// The templates a pour emitter's grains are drawn from, and its share of each: one per type and
// scale it releases; a uniform or lognormal size in kSizeBins equal-count bins per type, each at
// the cube root of its mean scale^3 (the bin's mass per grain).
std::vector<std::pair<GrainTemplate, double>> pour_templates(const Emitter& e) {
  std::map<std::uint16_t, std::vector<double>> scales;  // per type, its grains' scales
  for (const GrainDraw& d : emitter_grain_draws(e)) scales[d.type].push_back(d.scale);
  const bool continuous =
      e.size.distribution == SizeDistribution::Uniform || e.size.distribution == SizeDistribution::Lognormal;
  const double total = static_cast<double>(e.count);
  std::vector<std::pair<GrainTemplate, double>> out;
  for (auto& [type, list] : scales) {
    std::sort(list.begin(), list.end());
    if (!continuous) {
      for (std::size_t i = 0; i < list.size();) {
        std::size_t j = i;
        while (j < list.size() && list[j] == list[i]) ++j;
        out.push_back({{type, list[i]}, static_cast<double>(j - i) / total});
        i = j;
      }
      continue;
    }
    const std::size_t bins = std::min(kSizeBins, list.size());
    for (std::size_t b = 0; b < bins; ++b) {
      const std::size_t lo = b * list.size() / bins, hi = (b + 1) * list.size() / bins;
      double cubes = 0;
      for (std::size_t i = lo; i < hi; ++i) cubes += list[i] * list[i] * list[i];
      out.push_back(
          {{type, std::cbrt(cubes / static_cast<double>(hi - lo))}, static_cast<double>(hi - lo) / total});
    }
  }
  return out;
}

void plan_pours(DeckPlan& plan) {
  for (const Emitter& e : plan.scene.emitters) {
    if (e.type != EmitterType::Pour) continue;
    const double bound = emitter_bound(plan.scene, e);
    plan.box.add(e.min, bound);
    plan.box.add(e.max, bound);
    if (e.rate * plan.dt > 1.0) {
      refuse(plan.scene, fmt::format("a pour rate of {} grains/s is more than one grain per step of {:.3g} s (fix "
                                     "deposit inserts at most one)", e.rate, plan.dt));
    }
    PourEvent event{static_cast<std::int64_t>(std::llround(e.start / plan.dt)), &e, {}};
    for (const auto& [t, share] : pour_templates(e)) {
      // A named copy: clang 14 cannot capture a structured binding in a lambda.
      const GrainTemplate& wanted = t;
      auto it = std::find_if(plan.templates.begin(), plan.templates.end(), [&](const GrainTemplate& u) {
        return u.type == wanted.type && u.scale == wanted.scale;
      });
      const auto k = static_cast<std::size_t>(it - plan.templates.begin());
      if (it == plan.templates.end()) plan.templates.push_back(t);
      event.molfrac.resize(plan.templates.size(), 0.0);
      event.molfrac[k] += share;
    }
    plan.pours.push_back(event);
  }
  for (PourEvent& p : plan.pours) p.molfrac.resize(plan.templates.size(), 0.0);
  std::stable_sort(plan.pours.begin(), plan.pours.end(),
                   [](const PourEvent& a, const PourEvent& b) { return a.step < b.step; });
}

// The mean mass (kg) and particle radius (m) of the grains of `material` (every grain when none
// is of it), in the initial world and the pours, for the reference contacts of its atom type.
std::pair<double, double> mean_grain(const DeckPlan& plan, std::optional<std::uint16_t> material) {
  const World& w = plan.world;
  std::vector<std::pair<double, double>> grains;  // mass, radius
  for (std::size_t b = plan.fixtures; b < w.bodies.size(); ++b) {
    if (!is_dynamic(w, b)) continue;  // a state may hold static bodies after the grains (a silo's rim)
    const std::uint32_t first = w.bodies.first_particle[b];
    if (!material || w.particles.material[first] == *material)
      grains.emplace_back(1.0 / w.bodies.inverse_mass[b], w.particles.radius[first]);
  }
  for (const PourEvent& p : plan.pours) {
    for (const GrainDraw& d : emitter_grain_draws(*p.emitter)) {
      if (material && plan.scene.grains[d.type].material != *material) continue;
      const GrainShape g = scaled_grain(plan.scene, d.type, d.scale);
      grains.emplace_back(g.mass, g.particle_radius);
    }
  }
  if (grains.empty() && material) return mean_grain(plan, std::nullopt);
  if (grains.empty()) return {plan.kinds.front().shape.mass, plan.kinds.front().shape.particle_radius};
  // One size: that grain's figures exactly (no rounding in a mean).
  if (std::all_of(grains.begin(), grains.end(), [&](const auto& g) { return g == grains.front(); }))
    return grains.front();
  double mass = 0, radius = 0;
  for (const auto& [m, r] : grains) {
    mass += m;
    radius += r;
  }
  const auto n = static_cast<double>(grains.size());
  return {mass / n, radius / n};
}

void plan_atom_types(DeckPlan& plan) {
  const World& w = plan.world;
  for (std::uint16_t m = 0; m < w.materials.size(); ++m) {
    const auto [mass, radius] = mean_grain(plan, m);
    plan.types.push_back({m, mass, radius});
  }
  plan.body_type.assign(w.bodies.size(), 0);
  for (const GrainKind& k : plan.kinds) plan.dynamic_types.insert(plan.scene.grains[k.type].material + 1);
  // Dynamic props (fixtures that move): one atom type each. Grains follow the fixtures.
  for (std::size_t b = 0; b < plan.fixtures; ++b) {
    if (!is_dynamic(w, b)) continue;
    const std::uint32_t first = w.bodies.first_particle[b];
    plan.types.push_back({w.particles.material[first], 1.0 / w.bodies.inverse_mass[b], w.particles.radius[first]});
    plan.body_type[b] = static_cast<int>(plan.types.size());
    plan.dynamic_types.insert(plan.body_type[b]);
  }
}

// The plan of the scene's initial world, or of `state` run as `run` says (export_lammps_state).
DeckPlan make_plan(const Scene& scene, const World* state = nullptr, const LammpsStateRun* run = nullptr) {
  DeckPlan plan(scene, state ? *state : make_world(scene));
  plan.state = run;
  plan.fixtures = fixture_bodies(scene, state ? make_world(scene) : plan.world);
  check_exportable(scene, plan.world);
  std::string warning;
  plan.dt = run && run->dt > 0 ? run->dt : resolve_time_step(scene, plan.world, &warning);
  const double duration = run ? run->duration : scene.simulation.duration;
  if (!(duration > 0)) refuse(scene, fmt::format("a duration of {} s to run the state for", duration));
  plan.steps = static_cast<std::int64_t>(std::ceil(duration / plan.dt - 1e-9));
  plan.mol = molecule_ids(plan.world, &plan.rigid_count, &plan.dynamic_count);
  plan_geometry(plan);
  if (!run) plan_pours(plan);
  if (plan.dynamic_count == 0 && plan.pours.empty()) refuse(scene, "the scene has no dynamic bodies and no pour emitter");
  if (plan.box.lo.x() > plan.box.hi.x()) plan.box.add(Eigen::Vector3d::Zero(), plan.max_radius);
  plan.box.lo.array() -= 4 * plan.max_radius;
  plan.box.hi.array() += 4 * plan.max_radius;
  plan.g_ref = std::max(scene.gravity.norm(), 1e-3);
  plan_atom_types(plan);
  return plan;
}

// The molecule files: grain.mol for one template (the first grain type at scale 1 when no emitter
// pours), grain1.mol, grain2.mol ... for several.
std::vector<std::string> template_files(const DeckPlan& plan) {
  if (plan.templates.size() <= 1) return {"grain.mol"};
  std::vector<std::string> files;
  for (std::size_t k = 0; k < plan.templates.size(); ++k) files.push_back(fmt::format("grain{}.mol", k + 1));
  return files;
}

// Where LAMMPS does not do exactly what tetrasand does (LammpsDeck::approximations).
std::vector<std::string> approximations(const DeckPlan& plan) {
  const Scene& scene = plan.scene;
  std::vector<std::string> out = {
      scene.simulation.step.tangential == TangentialModel::Spring
          ? "tangential force: tetrasand's spring (k_t = 8 G* sqrt(R* delta)) becomes mindlin with the same k_t; its "
            "viscous part gamma_s scales with the normal damping in LAMMPS (as delta^(1/4)), equal at the overlap of "
            "one grain resting on another"
          : "tangential force: tetrasand's constant viscous gamma_s becomes linear_nohistory, whose damping scales "
            "with the normal damping (as delta^(1/4)); equal at the overlap of one grain resting on another",
      "integrator: LAMMPS fix rigid/small is velocity Verlet with Richardson quaternion updates; tetrasand uses " +
          std::string(scene.simulation.step.integrator == Integrator::ForwardEuler ? "forward Euler (thesis 3.44-3.50)"
                                                                                   : "semi-implicit Euler"),
      "no velocity (CFL) or overlap clamps in LAMMPS: results differ only where tetrasand reports clamps",
  };
  if (!plan.world.walls.cylinders.empty()) {
    out.push_back(
        "cylinder walls: LAMMPS uses the wall's curvature in the effective radius (R* = r R/(R - r) inside a "
        "cylinder of radius R); tetrasand treats walls as flat (R* = r)");
  }
  if (std::any_of(scene.props.begin(), scene.props.end(), [](const Prop& p) { return p.motion == MotionType::Dynamic; })) {
    out.push_back(
        "dynamic props: gravity acts on the atoms (weighted to the body's mass), whose centroid may sit slightly off "
        "the mesh's centre of mass: a small gravity torque tetrasand does not have");
    out.push_back(
        "dynamic props: each has its own atom type, so its tangential damping is matched at its own mass, at the "
        "overlap its whole weight would make on one contact; spread over many contacts the overlaps are smaller "
        "and LAMMPS's damping (~ delta^(1/4)) somewhat lower than tetrasand's gamma_s");
  }
  if (plan.kinds.size() > 1) {
    out.push_back(
        "grain sizes: each material has one atom type, its tangential damping matched at the material's mean "
        "grain "
        "(mass and radius); grains of other sizes see LAMMPS's damping scale as sqrt(m*) and R*^(1/4) where "
        "tetrasand's gamma_s is constant");
  }
  if (std::any_of(plan.pours.begin(), plan.pours.end(), [](const PourEvent& p) {
        const SizeDistribution d = p.emitter->size.distribution;
        return d == SizeDistribution::Uniform || d == SizeDistribution::Lognormal;
      })) {
    out.push_back(
        fmt::format("pour emitters with a uniform or lognormal size: fix deposit draws from {} molecule "
                    "templates per grain "
                    "type, one per equal-count size bin at the bin's mass-mean scale, not from the "
                    "continuous distribution",
                    kSizeBins));
  }
  if (!plan.pours.empty()) {
    out.push_back(
        "pour emitters: fix deposit inserts one grain every round(1/(rate dt)) steps at random free sites of the same "
        "region, with random orientations: the same statistics, not the same grains");
  }
  return out;
}

// The deck's lines, one section at a time.
class Script {
 public:
  void line(const std::string& s) { text_ += s + "\n"; }
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

// What this is, how to run it, what maps exactly and what does not.
void header_section(const DeckPlan& plan, const std::vector<std::string>& approximations, Script& out) {
  const World& w = plan.world;
  out.line("# LAMMPS input deck written by `tetrasand export lammps` from " + plan.scene.file.filename().string());
  out.line("#");
  out.line("# Run:      lmp -in in.tetrasand                 (serial)");
  out.line("#           mpirun -np 64 lmp -in in.tetrasand   (MPI; LAMMPS 29 Sep 2021 or later with GRANULAR, RIGID, MOLECULE)");
  out.line("# Files:    data.tetrasand  every particle of the initial state (grains, props, rough walls), molecule = body");
  out.line("#           bodies.rigid    explicit mass, centre of mass, world-frame inertia, velocity, angular momentum");
  out.line("#                           of every dynamic body (LAMMPS would sum the overlapping spheres instead)");
  out.line(plan.templates.size() > 1
               ? fmt::format("#           grain1.mol ...  the {} grain templates, a grain type at one size "
                             "each (fix deposit, pour emitters)",
                             plan.templates.size())
               : "#           grain.mol       the grain template (used by fix deposit for pour emitters)");
  out.line("# Output:   log.lammps (thermo every [output] every steps), particles.dump, final.dump (last state)");
  out.line("# Units:    SI (m, kg, s, Pa), as the scene file.");
  out.line(fmt::format("# Scene:    {} dynamic bodies, {} frozen particles (static/kinematic), {} smooth planes, {} "
                       "smooth cylinders, {} pour emitters", plan.dynamic_count, plan.frozen_particles,
                       w.walls.planes.size(), w.walls.cylinders.size(), plan.pours.size()));
  out.line(fmt::format("#           dt = {:.6g} s, {} steps = {:.6g} s simulated", plan.dt, plan.steps,
                       plan.dt * static_cast<double>(plan.steps)));
  out.line("#");
  out.line("# Same as tetrasand: positions, radii, body masses and inertia, gravity, dt, duration; Hertz stiffness");
  out.line("#   (hertz/material with E = 2 E*, nu = 0, so LAMMPS's E_eff is tetrasand's mixed E*); Tsuji normal damping");
  out.line("#   (the restitution given is the one whose LAMMPS Tsuji alpha(e) equals tetrasand's damping strength, which");
  out.line("#   tetrasand calibrated so that the clamped contact rebounds with the scene's restitution; limit_damping is");
  out.line("#   that clamp); Coulomb friction; damping by the rigid bodies' masses; rough walls as frozen particles");
  out.line("#   (fix freeze, infinite mass in the contact), smooth walls as fix wall/gran (wall/gran/region off-axis).");
  out.line("# Not the same:");
  for (const std::string& a : approximations) out.line("#   - " + a);
  out.line("");
}

// Units, atoms, the data file, groups and neighbour lists.
void setup_section(const DeckPlan& plan, Script& out) {
  out.line("units           si");
  out.line("atom_style      sphere");
  out.line("atom_modify     map array");
  out.line("dimension       3");
  out.line("boundary        m m m");
  out.line("newton          off");
  out.line(fmt::format("comm_modify     vel yes cutoff {}", num(plan.max_body_extent + 2 * plan.max_radius + plan.skin())));
  out.line("fix             prop all property/atom mol ghost yes");
  out.line("read_data       data.tetrasand fix prop NULL Molecules");
  std::string molecules = "molecule        grain";
  for (const std::string& f : template_files(plan)) molecules += fmt::format(" {}", f);
  out.line(plan.pours.empty() ? "" : molecules);
  out.line("");
  const std::int64_t first_frozen = static_cast<std::int64_t>(plan.dynamic_count) + 1;
  const std::int64_t last_id = static_cast<std::int64_t>(plan.world.bodies.size());
  out.line(plan.dynamic_count > 0 ? fmt::format("group           dynamic molecule <> 1 {}", plan.dynamic_count)
                                  : "group           dynamic empty");
  if (plan.dynamic_count > plan.rigid_count) {
    out.line(plan.rigid_count > 0 ? fmt::format("group           rigid molecule <> 1 {}", plan.rigid_count)
                                  : "group           rigid empty");
    out.line(fmt::format("group           spheres molecule <> {} {}", plan.rigid_count + 1, plan.dynamic_count));
  }
  out.line(first_frozen <= last_id ? fmt::format("group           frozen molecule <> {} {}", first_frozen, last_id)
                                   : "group           frozen empty");
  out.line(fmt::format("neighbor        {} bin", num(plan.skin())));
  out.line("neigh_modify    delay 0 every 1 check yes exclude molecule/intra all exclude group frozen frozen");
  out.line("");
}

// One coefficient set per pair of atom types.
void contact_section(const DeckPlan& plan, Script& out) {
  const std::vector<AtomType>& types = plan.types;
  const std::size_t materials = plan.world.materials.size();
  out.line("# Contacts: one coefficient set per pair of materials (atom type = material index + 1).");
  out.line("pair_style      granular");
  for (std::size_t a = 0; a < types.size(); ++a) {
    for (std::size_t b = a; b < types.size(); ++b) {
      const PairModel m = pair_model(plan.scene, plan.world.materials[types[a].material],
                                     plan.world.materials[types[b].material], plan.type_pair(a, b));
      out.line(fmt::format("pair_coeff      {} {} {}   # {}{} - {}{}", a + 1, b + 1, granular_model(m),
                           plan.material_name(types[a].material), a < materials ? "" : " (dynamic prop)",
                           plan.material_name(types[b].material), b < materials ? "" : " (dynamic prop)"));
    }
  }
  out.line("");
}

// Frozen particles, rigid bodies, gravity and kinematic moves.
void bodies_section(const DeckPlan& plan, Script& out) {
  const World& w = plan.world;
  if (plan.frozen_particles > 0) out.line("fix             freeze frozen freeze");
  // Gravity before the rigid bodies: fix rigid/small sums its atoms' forces in its setup, in the
  // order the fixes were defined, so a gravity defined after it is missing from the first half-step
  // (measured: every body 2.45 um high after 0.05 s at dt = 10 us, g dt t / 2).
  const double g = plan.scene.gravity.norm();
  if (g > 0) {
    out.line(fmt::format("fix             gravity dynamic gravity {} vector {}", num(g), vec(plan.scene.gravity / g)));
  }
  const std::string rigid_mol = plan.pours.empty() ? "" : " mol grain";
  const bool spheres = plan.dynamic_count > plan.rigid_count;
  if (!spheres || plan.rigid_count > 0) {
    out.line(fmt::format("fix             rb {} rigid/small molecule{}{}", spheres ? "rigid" : "dynamic",
                         plan.rigid_count > 0 ? " infile bodies.rigid" : "", rigid_mol));
  }
  if (spheres) out.line("fix             spheres spheres nve/sphere");
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (w.bodies.motion[b] != MotionType::Kinematic) continue;
    const std::int64_t id = plan.mol[b];
    out.line(fmt::format("group           kinematic{} molecule {}", id, id));
    const Eigen::Vector3d& omega = w.bodies.angular_velocity[b];
    if (omega.norm() > 0) {
      out.line(fmt::format("fix             move{} kinematic{} move rotate {} {} {} units box", id, id,
                           vec(w.bodies.position[b]), vec(omega.normalized()), num(2 * std::numbers::pi / omega.norm())));
    } else {
      out.line(fmt::format("fix             move{} kinematic{} move linear {} units box", id, id,
                           vec(w.bodies.linear_velocity[b])));
    }
  }
  out.line("");
}

// The groups each wall acts on: all dynamic atoms, or one group per dynamic atom type (each has its
// own coefficients against the wall).
std::vector<std::pair<std::string, int>> wall_groups(const DeckPlan& plan, Script& out) {
  std::vector<std::pair<std::string, int>> groups;
  if (plan.dynamic_types.size() == 1) {
    groups.emplace_back("dynamic", *plan.dynamic_types.begin());
    return groups;
  }
  for (int t : plan.dynamic_types) {
    out.line(fmt::format("group           type{} type {}", t, t));
    out.line(fmt::format("group           dynamic{} intersect dynamic type{}", t, t));
    groups.emplace_back(fmt::format("dynamic{}", t), t);
  }
  return groups;
}

// Smooth walls, one fix per wall and dynamic atom type.
void walls_section(const DeckPlan& plan, Script& out) {
  const auto groups = wall_groups(plan, out);
  int wall_id = 0;
  for (const PlaneWall& p : plan.world.walls.planes) {
    ++wall_id;
    int axis = 0;
    const bool aligned = axis_aligned(p.normal, &axis);
    if (!aligned) {
      out.line(fmt::format("region          wall{} plane {} {} side in units box", wall_id, vec(p.point), vec(p.normal)));
    }
    for (const auto& [group, type] : groups) {
      const std::string model = plan.wall_model(type, p.material);
      if (aligned) {
        const std::string at = num(p.point[axis]);
        const std::string bounds = p.normal[axis] > 0 ? at + " NULL" : "NULL " + at;
        out.line(fmt::format("fix             wall{}_{} {} wall/gran granular {} {}plane {}", wall_id, type, group,
                             model, "xyz"[axis], bounds));
      } else {
        out.line(fmt::format("fix             wall{}_{} {} wall/gran/region granular {} region wall{}", wall_id,
                             type, group, model, wall_id));
      }
    }
  }
  for (const CylinderWall& c : plan.world.walls.cylinders) {
    ++wall_id;
    auto bound = [](double z) { return std::abs(z) >= 1e29 ? std::string("INF") : num(z); };
    out.line(fmt::format("region          wall{} cylinder z {} {} {} {} {} side in open 1 open 2 units box", wall_id,
                         num(c.axis.x()), num(c.axis.y()), num(c.radius), bound(c.z_min), bound(c.z_max)));
    for (const auto& [group, type] : groups) {
      out.line(fmt::format("fix             wall{}_{} {} wall/gran/region granular {} region wall{}", wall_id,
                           type, group, plan.wall_model(type, c.material), wall_id));
    }
  }
  out.line("");
}

// Thermo: the translational and rotational kinetic energies of the rigid bodies (c_ket, c_ker)
// and of the free spheres (c_kes, c_kers), whichever the deck has.
void output_section(const DeckPlan& plan, Script& out) {
  out.line(fmt::format("timestep        {}", num(plan.dt)));
  const bool spheres = plan.dynamic_count > plan.rigid_count, rigid = !spheres || plan.rigid_count > 0;
  std::string energies;
  if (rigid) {
    const std::string group = spheres ? "rigid" : "dynamic";
    out.line(fmt::format("compute         ket {} ke/rigid rb", group));
    out.line(fmt::format("compute         ker {} erotate/rigid rb", group));
    energies += " c_ket c_ker";
  }
  if (spheres) {
    out.line("compute         kes spheres ke");
    out.line("compute         kers spheres erotate/sphere");
    energies += " c_kes c_kers";
  }
  out.line("thermo_style    custom step time atoms" + energies);
  out.line("thermo_modify   norm no lost error");
  const std::int64_t every = plan.state && plan.state->thermo_every > 0 ? plan.state->thermo_every
                                                                       : plan.scene.output.every;
  out.line(fmt::format("thermo          {}", every));
  const std::int64_t dump_every = plan.state ? plan.state->dump_every : plan.scene.output.every;
  if (dump_every > 0) {
    out.line(fmt::format("dump            particles dynamic custom {} particles.dump id mol type x y z radius",
                         dump_every));
  }
  if (plan.state && !plan.state->before_run.empty()) {
    for (const std::string& command : plan.state->before_run) out.line(command);
    out.line("thermo_modify   norm no lost error");  // a new thermo_style resets it
  }
  out.line("");
}

// The run, split where pour emitters start.
void run_section(const DeckPlan& plan, Script& out) {
  std::int64_t at = 0;
  int pour_id = 0;
  for (const PourEvent& p : plan.pours) {
    const std::int64_t start = std::min(p.step, plan.steps);
    if (start > at) out.line(fmt::format("run             {}", start - at));
    at = std::max(at, start);
    const Emitter& e = *p.emitter;
    ++pour_id;
    const auto every = std::max<std::int64_t>(1, std::llround(1.0 / (e.rate * plan.dt)));
    out.line(fmt::format("region          pour{} block {} {} {} {} {} {} units box", pour_id, num(e.min.x()),
                         num(e.max.x()), num(e.min.y()), num(e.max.y()), num(e.min.z()), num(e.max.z())));
    double radius = 0;  // m, the largest sphere this emitter releases
    std::string molfrac;
    for (std::size_t k = 0; k < plan.templates.size(); ++k) {
      molfrac += fmt::format(" {}", num(p.molfrac[k]));
      const GrainTemplate& t = plan.templates[k];
      if (p.molfrac[k] > 0) radius = std::max(radius, t.scale * plan.scene.grains[t.type].radius);
    }
    out.line(fmt::format(
        "fix             pour{} dynamic deposit {} 0 {} {} region pour{} mol grain{} rigid rb near {} "
        "attempt 100 vx {} {} vy {} {} vz {} {} units box",
        pour_id, e.count, every, 1000 + e.seed % 1000000, pour_id,
        plan.templates.size() > 1 ? fmt::format(" molfrac{}", molfrac) : std::string(), num(2.02 * radius),
        num(e.velocity.x()), num(e.velocity.x()), num(e.velocity.y()), num(e.velocity.y()),
        num(e.velocity.z()), num(e.velocity.z())));
  }
  if (plan.steps > at) out.line(fmt::format("run             {}", plan.steps - at));
  // Full precision: the last state is what other codes compare against.
  out.line("write_dump      dynamic custom final.dump id mol type x y z radius modify format float %.17g");
}

}  // namespace

double lammps_tsuji_alpha(double e) {
  return 1.2728 - 4.2783 * e + 11.087 * e * e - 22.348 * std::pow(e, 3) + 27.467 * std::pow(e, 4) -
         18.022 * std::pow(e, 5) + 4.8218 * std::pow(e, 6);
}

double lammps_restitution_for_alpha(double alpha) {
  const double top = lammps_tsuji_alpha(0.0), bottom = lammps_tsuji_alpha(1.0);
  if (!(alpha <= top && alpha >= std::min(bottom, 0.0))) {
    throw InputError(fmt::format("LAMMPS Tsuji damping reaches alpha in [{:.4g}, {:.4g}] only; {:.6g} requested "
                                 "(restitution too low)", bottom, top, alpha));
  }
  if (alpha <= bottom) return 1.0;
  double lo = 0.0, hi = 1.0;  // alpha(lo) >= alpha >= alpha(hi): the polynomial decreases on [0, 1]
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (lammps_tsuji_alpha(mid) > alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {

// The deck's files by name, their text built whole before any is written.
std::vector<std::pair<std::string, std::string>> deck_texts(const DeckPlan& plan, const LammpsDeck& deck) {
  const Scene& scene = plan.scene;
  std::vector<std::pair<std::string, std::string>> texts;
  Script in;
  header_section(plan, deck.approximations, in);
  setup_section(plan, in);
  contact_section(plan, in);
  bodies_section(plan, in);
  walls_section(plan, in);
  output_section(plan, in);
  run_section(plan, in);
  // The input script after the files it reads, as a deck is complete once its script is there.
  texts.emplace_back("data.tetrasand", data_file(plan.world, plan.mol, plan.body_type, plan.types.size(),
                                                 plan.box, plan.state != nullptr));
  texts.emplace_back("bodies.rigid", bodies_file(plan.world, plan.mol, plan.rigid_count));
  texts.emplace_back("in.tetrasand", in.text());
  const std::vector<std::string> files = template_files(plan);
  for (std::size_t k = 0; k < files.size(); ++k) {
    const GrainTemplate& t = k < plan.templates.size() ? plan.templates[k] : GrainTemplate{0, 1.0};
    texts.emplace_back(files[k],
                       molecule_file(scaled_grain(scene, t.type, t.scale), scene.grains[t.type].material));
  }
  return texts;
}

LammpsDeck write_deck(const DeckPlan& plan, const fs::path& dir) {
  const Scene& scene = plan.scene;
  LammpsDeck deck;
  deck.dt = plan.dt;
  deck.steps = plan.steps;
  deck.dynamic_bodies = plan.dynamic_count;
  deck.frozen_particles = plan.frozen_particles;
  deck.approximations = approximations(plan);
  std::vector<std::pair<std::string, std::string>> texts;
  try {
    texts = deck_texts(plan, deck);
  } catch (const NonFiniteNumber& e) {
    refuse(scene,
           fmt::format("the deck would hold the non-finite number {} (a value of the scene or state, or "
                       "the arithmetic on it, overflows: give finite values of a size the scene's "
                       "checks accept, as `tetrasand sim` requires)",
                       e.value()));
  }
  fs::create_directories(dir);
  const std::vector<fs::path> inputs{scene.file};
  deck.input = dir / "in.tetrasand";
  deck.files = {deck.input, dir / "data.tetrasand", dir / "bodies.rigid"};
  for (const auto& [name, text] : texts) {
    write_file_atomically(dir / name, text, inputs);
    if (name.ends_with(".mol")) deck.files.push_back(dir / name);
  }
  return deck;
}

}  // namespace

LammpsDeck export_lammps(const Scene& scene, const fs::path& dir) { return write_deck(make_plan(scene), dir); }

LammpsDeck export_lammps_state(const Scene& scene, const World& state, const LammpsStateRun& run, const fs::path& dir) {
  return write_deck(make_plan(scene, &state, &run), dir);
}

}  // namespace ts::exporter
