#pragma once
// From a parsed scene (scene/scene.h) to the simulator's world (sim/world.h): materials, smooth walls,
// rough walls as static particle bodies, props from their body files, the grains of the emitters,
// and the time-step bound of the scene's contacts. Implemented in scene/scene_world.cpp.
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "sim/grain.h"
#include "scene/grain_mix.h"
#include "scene/lattice.h"
#include "scene/scene.h"
#include "sim/time_step.h"
#include "sim/world.h"
#include "scene/uses_engine.h"

namespace ts::scene {

// What the smooth walls and the non-grain bodies of a world stand for in the scene, for messages.
struct WorldSources {
  std::vector<std::string> smooth_walls;  // planes, then cylinders: "the plane of [[boundary]] at line 12"
  std::vector<std::string> bodies;        // the first bodies (rough walls, props), in world order
  std::vector<std::uint32_t> prop_bodies;  // the body of each [[prop]], in scene order
};

// The initial world of a scene: materials, smooth walls, rough walls as static particle bodies,
// props, and the grains of the fill and column emitters. Pour emitters run through PourEmitter.
// Every size the scene implies is checked first (scene/scene_limits.h). `sources`, when given, names
// the walls and bodies.
World make_world(const Scene& scene, WorldSources* sources = nullptr);

// The bodies make_world adds before the grains (rough walls and props; world order): grains are the
// bodies from this index on (emitters only append grains).
std::size_t fixture_bodies(const Scene& scene, const World& world);

// The bodies of each [[prop]] in the world (scene order): one, or one per sphere of a breakable prop.
struct BodyRange {
  std::uint32_t first = 0, count = 0;
  bool breakable = false;
};
std::vector<BodyRange> prop_body_ranges(const Scene& scene, const World& world);

// A kind of contact a grain of the scene will see, and what it is with.
struct SceneContactCase {
  ContactCase contact;
  double smaller_radius = 0;  // m, of the two spheres
  double load_mass = 0;       // kg: the heavier grain of the contact, whose weight it holds at rest
  std::string grain;          // "a grain", or the GrainKind's name when there are several kinds
  std::string partner;        // "another grain", "the boundary at line 12", a WorldSources body name
};
// For each GrainKind (scene_grain_kinds): against each kind (itself included), each [[boundary]],
// and each rough wall and prop body. With one kind, grain-grain, grain-boundary and grain-body.
std::vector<SceneContactCase> scene_contact_cases(const Scene& scene, const World& world,
                                                  const WorldSources* sources = nullptr);

// The impact speed the automatic time step is sized for, and the key that sets it.
struct DesignSpeed {
  double speed = 0;  // m/s
  std::string key;   // "simulation.max_impact_speed", "gravity" (free fall), "emitter.velocity", ...
  int line = 0;      // of the [[emitter]] or [[prop]] table; 0: the key's own line
};
// simulation.max_impact_speed, else free fall over the scene's height plus the fastest launch
// (at least 0.5 m/s).
DesignSpeed scene_design_speed(const Scene& scene, const World& world);

// The particle kinds of the Rayleigh bound: each GrainKind's spheres and each rough boundary's.
std::vector<ParticleKind> scene_particle_kinds(const Scene& scene);

// The bonds' share of the time-step bound: the shortest sim::bond_time_step over the bond materials.
struct BondStepBound {
  double step = std::numeric_limits<double>::infinity();  // s; +inf without bonds
  int material = -1;                                     // the [[bond_material]] that sets it
};
BondStepBound scene_bond_time_step(const World& world);

// The shortest bond time step a scene may need (s): below it a bond material is refused, naming its E.
inline constexpr double kShortestBondTimeStep = 1e-9;

// The time-step bound for the scene's contact kinds at `impact_speed` (m/s; 0: the design speed), and
// its bonds' (TimeStepBound::bonds). Throws ts::InputError naming bond_material.E when the bonds need
// a step below kShortestBondTimeStep.
TimeStepBound scene_time_step_bound(const Scene& scene, const World& world, double impact_speed = 0);

// Offsets from the hole's centre of fixed spheres of `radius` lining a round hole in a rough plane
// (in-plane axes t1, t2, normal n into the free side; sphere tops in the plane, as the lattice's):
// centres on a circle of hole_radius + radius, at most `radius` apart, so the opening is a disc of
// 2 hole_radius to within bumps of 0.14 radius (a lattice with the spheres reaching into the hole left
// out opens up to a spacing wider, unevenly).
std::vector<Eigen::Vector3d> round_hole_rim(const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                                            const Eigen::Vector3d& n, double hole_radius, double radius);

// Where a pour emitter stands: its next site, grains released, and its generator's state (text of
// std::mt19937_64's operator<<).
struct PourProgress {
  std::uint64_t next_site = 0, emitted = 0;
  std::string rng;
};

// Releases a pour emitter's grains as time passes, at free lattice sites of its region.
class PourEmitter {
 public:
  PourEmitter(const Scene& scene, const Emitter& emitter);
  // Adds the grains due by world.time whose site is free; returns how many were added.
  std::size_t emit(World& world);
  bool finished() const { return emitted_ == emitter_.count; }
  // For checkpoints: where it stands, and going on from there (the sites are the constructor's).
  PourProgress progress() const;
  void restore(const PourProgress& progress);

 private:
  std::vector<GrainSpec> types_;   // the scene's grain types
  std::vector<double> densities_;  // kg/m^3, of each type's material
  std::vector<GrainDraw> draws_;   // type and scale of each grain, in release order
  double bound_ = 0;               // m, bounding radius of the emitter's largest grain
  Emitter emitter_;
  std::vector<Eigen::Vector3d> sites_;  // m, lattice sites of the region
  std::size_t next_site_ = 0, emitted_ = 0;
  std::mt19937_64 rng_;
};

}  // namespace ts::scene
