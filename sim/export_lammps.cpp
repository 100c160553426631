// `tetrasand export lammps`: the scene as a LAMMPS deck (see export_lammps.h for the mapping).
#include "sim/export_lammps.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "core/atomic_file.h"
#include "core/error.h"
#include "sim/grain.h"
#include "sim/scene_runner.h"

namespace ts::sim {
namespace {

namespace fs = std::filesystem;

// Round-trip precision for every number LAMMPS reads back.
std::string num(double v) { return fmt::format("{:.17g}", v); }
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

// Molecule IDs: dynamic bodies 1..D in world order, then the static and kinematic ones.
std::vector<std::int64_t> molecule_ids(const World& w, std::size_t* dynamic_count) {
  std::vector<std::int64_t> ids(w.bodies.size());
  std::int64_t next = 1;
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (is_dynamic(w, b)) ids[b] = next++;
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
                      std::size_t type_count, const Box& box) {
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
  out += "\nMolecules\n\n";
  for (std::size_t i = 0; i < x.size(); ++i) out += fmt::format("{} {}\n", i + 1, mol[w.particles.body[i]]);
  return out;
}

// fix rigid/small infile: ID masstotal xcm ycm zcm ixx iyy izz ixy ixz iyz vxcm vycm vzcm lx ly lz
// ixcm iycm izcm, inertia about the centre of mass in the world frame, angular momentum L = I w.
std::string bodies_file(const World& w, const std::vector<std::int64_t>& mol, std::size_t dynamic_count) {
  std::string out = "# tetrasand export lammps: explicit mass (kg), centre of mass (m), world-frame inertia (kg m^2)\n";
  out += "# ID masstotal xcm ycm zcm ixx iyy izz ixy ixz iyz vxcm vycm vzcm lx ly lz ixcm iycm izcm\n";
  out += fmt::format("{}\n", dynamic_count);
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (!is_dynamic(w, b)) continue;
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
  if (!w.tracks.empty()) {
    refuse(scene, "a keyframed kinematic prop (this export writes LAMMPS fix move linear/rotate, not a path)");
  }
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (w.bodies.motion[b] != MotionType::Kinematic) continue;
    if (w.bodies.linear_velocity[b].norm() > 0 && w.bodies.angular_velocity[b].norm() > 0) {
      refuse(scene, "a kinematic prop that both translates and spins (LAMMPS fix move does one or the other)");
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
};

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

LammpsDeck export_lammps(const Scene& scene, const fs::path& dir) {
  const World w = make_world(scene);
  check_exportable(scene, w);
  LammpsDeck deck;
  std::string warning;
  deck.dt = resolve_time_step(scene, w, &warning);
  deck.steps = static_cast<std::int64_t>(std::ceil(scene.simulation.duration / deck.dt - 1e-9));
  const GrainShape grain = make_tetrahedral_grain(scene.grain.radius, scene.grain.edge,
                                                  scene.materials[scene.grain.material].density);

  std::size_t dynamic_count = 0;
  const std::vector<std::int64_t> mol = molecule_ids(w, &dynamic_count);
  deck.dynamic_bodies = dynamic_count;
  double max_radius = grain.particle_radius, max_body_extent = 2 * grain.bounding_radius;  // m
  Box box;
  const std::vector<Eigen::Vector3d> x = particle_positions(w);
  for (std::size_t i = 0; i < x.size(); ++i) {
    box.add(x[i], w.particles.radius[i]);
    max_radius = std::max(max_radius, w.particles.radius[i]);
    if (!is_dynamic(w, w.particles.body[i])) ++deck.frozen_particles;
  }
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (is_dynamic(w, b)) max_body_extent = std::max(max_body_extent, 2 * w.bodies.bounding_radius[b]);
  }
  std::vector<PourEvent> pours;
  for (const Emitter& e : scene.emitters) {
    if (e.type != EmitterType::Pour) continue;
    box.add(e.min, grain.bounding_radius);
    box.add(e.max, grain.bounding_radius);
    if (e.rate * deck.dt > 1.0) {
      refuse(scene, fmt::format("a pour rate of {} grains/s is more than one grain per step of {:.3g} s (fix deposit "
                                "inserts at most one)", e.rate, deck.dt));
    }
    pours.push_back({static_cast<std::int64_t>(std::llround(e.start / deck.dt)), &e});
  }
  if (dynamic_count == 0 && pours.empty()) refuse(scene, "the scene has no dynamic bodies and no pour emitter");
  if (box.lo.x() > box.hi.x()) box.add(Eigen::Vector3d::Zero(), max_radius);
  box.lo.array() -= 4 * max_radius;
  box.hi.array() += 4 * max_radius;
  std::stable_sort(pours.begin(), pours.end(), [](const PourEvent& a, const PourEvent& b) { return a.step < b.step; });

  // Pair and wall coefficients (grain-grain and grain-wall reference contacts).
  // Atom types: materials first (type = material + 1), then one per dynamic prop.
  const double g_ref = std::max(scene.gravity.norm(), 1e-3);  // m/s^2, for the reference overlaps
  std::vector<AtomType> types;
  for (std::uint16_t m = 0; m < w.materials.size(); ++m) types.push_back({m, grain.mass, grain.particle_radius});
  std::vector<int> body_type(w.bodies.size(), 0);  // 0: the material's type
  std::set<int> dynamic_types{scene.grain.material + 1};
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (!is_dynamic(w, b)) continue;
    const std::uint32_t first = w.bodies.first_particle[b];
    const bool is_grain = w.bodies.particle_count[b] == 4 && w.particles.radius[first] == grain.particle_radius &&
                          w.particles.material[first] == scene.grain.material;
    if (is_grain) continue;
    types.push_back({w.particles.material[first], 1.0 / w.bodies.inverse_mass[b], w.particles.radius[first]});
    body_type[b] = static_cast<int>(types.size());
    dynamic_types.insert(body_type[b]);
  }
  auto type_pair = [&](std::size_t a, std::size_t b) {
    const AtomType &ta = types[a], &tb = types[b];
    return ReferenceContact{ta.mass * tb.mass / (ta.mass + tb.mass), ta.radius * tb.radius / (ta.radius + tb.radius),
                            std::min(ta.mass, tb.mass) * g_ref};
  };
  auto type_wall = [&](int t) {
    const AtomType& ta = types[static_cast<std::size_t>(t - 1)];
    return ReferenceContact{ta.mass, ta.radius, ta.mass * g_ref};
  };
  auto name = [&](std::uint16_t m) {
    return scene.material_names.size() > m ? scene.material_names[m] : std::to_string(m);
  };

  std::string in;
  auto line = [&](const std::string& s) { in += s + "\n"; };
  const double skin = 0.3 * 2 * max_radius;  // m
  deck.approximations = {
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
  if (!w.walls.cylinders.empty()) {
    deck.approximations.push_back(
        "cylinder walls: LAMMPS uses the wall's curvature in the effective radius (R* = r R/(R - r) inside a "
        "cylinder of radius R); tetrasand treats walls as flat (R* = r)");
  }
  if (std::any_of(scene.props.begin(), scene.props.end(), [](const Prop& p) { return p.motion == MotionType::Dynamic; })) {
    deck.approximations.push_back(
        "dynamic props: gravity acts on the atoms (weighted to the body's mass), whose centroid may sit slightly off "
        "the mesh's centre of mass: a small gravity torque tetrasand does not have");
    deck.approximations.push_back(
        "dynamic props: each has its own atom type, so its tangential damping is matched at its own mass, at the "
        "overlap its whole weight would make on one contact; spread over many contacts the overlaps are smaller "
        "and LAMMPS's damping (~ delta^(1/4)) somewhat lower than tetrasand's gamma_s");
  }
  if (!pours.empty()) {
    deck.approximations.push_back(
        "pour emitters: fix deposit inserts one grain every round(1/(rate dt)) steps at random free sites of the same "
        "region, with random orientations: the same statistics, not the same grains");
  }

  // Header: what this is, how to run it, what maps exactly and what does not.
  line("# LAMMPS input deck written by `tetrasand export lammps` from " + scene.file.filename().string());
  line("#");
  line("# Run:      lmp -in in.tetrasand                 (serial)");
  line("#           mpirun -np 64 lmp -in in.tetrasand   (MPI; LAMMPS 29 Sep 2021 or later with GRANULAR, RIGID, MOLECULE)");
  line("# Files:    data.tetrasand  every particle of the initial state (grains, props, rough walls), molecule = body");
  line("#           bodies.rigid    explicit mass, centre of mass, world-frame inertia, velocity, angular momentum");
  line("#                           of every dynamic body (LAMMPS would sum the overlapping spheres instead)");
  line("#           grain.mol       the grain template (used by fix deposit for pour emitters)");
  line("# Output:   log.lammps (thermo every [output] every steps), particles.dump, final.dump (last state)");
  line("# Units:    SI (m, kg, s, Pa), as the scene file.");
  line(fmt::format("# Scene:    {} dynamic bodies, {} frozen particles (static/kinematic), {} smooth planes, {} "
                   "smooth cylinders, {} pour emitters", dynamic_count, deck.frozen_particles, w.walls.planes.size(),
                   w.walls.cylinders.size(), pours.size()));
  line(fmt::format("#           dt = {:.6g} s, {} steps = {:.6g} s simulated", deck.dt, deck.steps,
                   deck.dt * static_cast<double>(deck.steps)));
  line("#");
  line("# Same as tetrasand: positions, radii, body masses and inertia, gravity, dt, duration; Hertz stiffness");
  line("#   (hertz/material with E = 2 E*, nu = 0, so LAMMPS's E_eff is tetrasand's mixed E*); Tsuji normal damping");
  line("#   (the restitution given is the one whose LAMMPS Tsuji alpha(e) equals tetrasand's damping strength, which");
  line("#   tetrasand calibrated so that the clamped contact rebounds with the scene's restitution; limit_damping is");
  line("#   that clamp); Coulomb friction; damping by the rigid bodies' masses; rough walls as frozen particles");
  line("#   (fix freeze, infinite mass in the contact), smooth walls as fix wall/gran (wall/gran/region off-axis).");
  line("# Not the same:");
  for (const std::string& a : deck.approximations) line("#   - " + a);
  line("");

  line("units           si");
  line("atom_style      sphere");
  line("atom_modify     map array");
  line("dimension       3");
  line("boundary        m m m");
  line("newton          off");
  line(fmt::format("comm_modify     vel yes cutoff {}", num(max_body_extent + 2 * max_radius + skin)));
  line("fix             prop all property/atom mol ghost yes");
  line("read_data       data.tetrasand fix prop NULL Molecules");
  line(pours.empty() ? "" : "molecule        grain grain.mol");
  line("");
  const std::int64_t first_frozen = static_cast<std::int64_t>(dynamic_count) + 1;
  const std::int64_t last_id = static_cast<std::int64_t>(w.bodies.size());
  line(dynamic_count > 0 ? fmt::format("group           dynamic molecule <> 1 {}", dynamic_count)
                         : "group           dynamic empty");
  line(first_frozen <= last_id ? fmt::format("group           frozen molecule <> {} {}", first_frozen, last_id)
                               : "group           frozen empty");
  line(fmt::format("neighbor        {} bin", num(skin)));
  line("neigh_modify    delay 0 every 1 check yes exclude molecule/intra all exclude group frozen frozen");
  line("");
  line("# Contacts: one coefficient set per pair of materials (atom type = material index + 1).");
  line("pair_style      granular");
  for (std::size_t a = 0; a < types.size(); ++a) {
    for (std::size_t b = a; b < types.size(); ++b) {
      const PairModel m = pair_model(scene, w.materials[types[a].material], w.materials[types[b].material], type_pair(a, b));
      line(fmt::format("pair_coeff      {} {} {}   # {}{} - {}{}", a + 1, b + 1, granular_model(m),
                       name(types[a].material), a < w.materials.size() ? "" : " (dynamic prop)",
                       name(types[b].material), b < w.materials.size() ? "" : " (dynamic prop)"));
    }
  }
  line("");
  if (deck.frozen_particles > 0) line("fix             freeze frozen freeze");
  const std::string rigid_mol = pours.empty() ? "" : " mol grain";
  line(fmt::format("fix             rb dynamic rigid/small molecule{}{}", dynamic_count > 0 ? " infile bodies.rigid" : "",
                   rigid_mol));
  const double g = scene.gravity.norm();
  if (g > 0) {
    line(fmt::format("fix             gravity dynamic gravity {} vector {}", num(g), vec(scene.gravity / g)));
  }
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    if (w.bodies.motion[b] != MotionType::Kinematic) continue;
    line(fmt::format("group           kinematic{} molecule {}", mol[b], mol[b]));
    const Eigen::Vector3d& omega = w.bodies.angular_velocity[b];
    if (omega.norm() > 0) {
      line(fmt::format("fix             move{} kinematic{} move rotate {} {} {} units box", mol[b], mol[b],
                       vec(w.bodies.position[b]), vec(omega.normalized()), num(2 * std::numbers::pi / omega.norm())));
    } else {
      line(fmt::format("fix             move{} kinematic{} move linear {} units box", mol[b], mol[b],
                       vec(w.bodies.linear_velocity[b])));
    }
  }
  line("");

  // Smooth walls, one fix per wall and dynamic atom type (each has its own coefficients).
  std::vector<std::pair<std::string, int>> wall_groups;
  if (dynamic_types.size() == 1) {
    wall_groups.emplace_back("dynamic", *dynamic_types.begin());
  } else {
    for (int t : dynamic_types) {
      line(fmt::format("group           type{} type {}", t, t));
      line(fmt::format("group           dynamic{} intersect dynamic type{}", t, t));
      wall_groups.emplace_back(fmt::format("dynamic{}", t), t);
    }
  }
  int wall_id = 0;
  for (const PlaneWall& p : w.walls.planes) {
    ++wall_id;
    int axis = 0;
    const bool aligned = axis_aligned(p.normal, &axis);
    if (!aligned) {
      line(fmt::format("region          wall{} plane {} {} side in units box", wall_id, vec(p.point), vec(p.normal)));
    }
    for (const auto& [group, type] : wall_groups) {
      const std::string model = granular_model(pair_model(scene, w.materials[types[static_cast<std::size_t>(type - 1)].material],
                                                          w.materials[p.material], type_wall(type)));
      if (aligned) {
        const std::string at = num(p.point[axis]);
        const std::string bounds = p.normal[axis] > 0 ? at + " NULL" : "NULL " + at;
        line(fmt::format("fix             wall{}_{} {} wall/gran granular {} {}plane {}", wall_id, type, group,
                         model, "xyz"[axis], bounds));
      } else {
        line(fmt::format("fix             wall{}_{} {} wall/gran/region granular {} region wall{}", wall_id,
                         type, group, model, wall_id));
      }
    }
  }
  for (const CylinderWall& c : w.walls.cylinders) {
    ++wall_id;
    auto bound = [](double z) { return std::abs(z) >= 1e29 ? std::string("INF") : num(z); };
    line(fmt::format("region          wall{} cylinder z {} {} {} {} {} side in open 1 open 2 units box", wall_id,
                     num(c.axis.x()), num(c.axis.y()), num(c.radius), bound(c.z_min), bound(c.z_max)));
    for (const auto& [group, type] : wall_groups) {
      const std::string model = granular_model(pair_model(scene, w.materials[types[static_cast<std::size_t>(type - 1)].material],
                                                          w.materials[c.material], type_wall(type)));
      line(fmt::format("fix             wall{}_{} {} wall/gran/region granular {} region wall{}", wall_id,
                       type, group, model, wall_id));
    }
  }
  line("");
  line(fmt::format("timestep        {}", num(deck.dt)));
  line("compute         ket dynamic ke/rigid rb");
  line("compute         ker dynamic erotate/rigid rb");
  line("thermo_style    custom step time atoms c_ket c_ker");
  line("thermo_modify   norm no lost error");
  line(fmt::format("thermo          {}", scene.output.every));
  line(fmt::format("dump            particles dynamic custom {} particles.dump id mol type x y z radius",
                   scene.output.every));
  line("");

  // The run, split where pour emitters start.
  std::int64_t at = 0;
  int pour_id = 0;
  for (const PourEvent& p : pours) {
    const std::int64_t start = std::min(p.step, deck.steps);
    if (start > at) line(fmt::format("run             {}", start - at));
    at = std::max(at, start);
    const Emitter& e = *p.emitter;
    ++pour_id;
    const auto every = std::max<std::int64_t>(1, std::llround(1.0 / (e.rate * deck.dt)));
    line(fmt::format("region          pour{} block {} {} {} {} {} {} units box", pour_id, num(e.min.x()),
                     num(e.max.x()), num(e.min.y()), num(e.max.y()), num(e.min.z()), num(e.max.z())));
    line(fmt::format("fix             pour{} dynamic deposit {} 0 {} {} region pour{} mol grain rigid rb near {} "
                     "attempt 100 vx {} {} vy {} {} vz {} {} units box",
                     pour_id, e.count, every, 1000 + e.seed % 1000000, pour_id, num(2.02 * grain.particle_radius),
                     num(e.velocity.x()), num(e.velocity.x()), num(e.velocity.y()), num(e.velocity.y()),
                     num(e.velocity.z()), num(e.velocity.z())));
  }
  if (deck.steps > at) line(fmt::format("run             {}", deck.steps - at));
  line("write_dump      dynamic custom final.dump id mol type x y z radius");

  fs::create_directories(dir);
  const std::vector<fs::path> inputs{scene.file};
  deck.input = dir / "in.tetrasand";
  write_file_atomically(dir / "data.tetrasand", data_file(w, mol, body_type, types.size(), box), inputs);
  write_file_atomically(dir / "bodies.rigid", bodies_file(w, mol, dynamic_count), inputs);
  write_file_atomically(dir / "grain.mol",
                        molecule_file(grain, scene.grain.material), inputs);
  write_file_atomically(deck.input, in, inputs);
  deck.files = {deck.input, dir / "data.tetrasand", dir / "bodies.rigid", dir / "grain.mol"};
  return deck;
}

}  // namespace ts::sim
