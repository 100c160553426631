#pragma once
// Hand-written scene files (TOML, SI units: m, kg, s, Pa). Every key is checked: a misspelt key is
// an error, never silently ignored, and every error names the file, the line and the key:
//   "pile.toml:12: material.E: must be > 0 (Pa)".
// The format, by example, is in assets/scenes/*.toml; load_scene() documents the keys it accepts
// through its error messages ("expected one of: ...").
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sim/bond_model.h"
#include "sim/contact_model.h"
#include "scene/servo.h"
#include "sim/stepper.h"
#include "sim/time_step.h"
#include "sim/world.h"
#include "scene/uses_engine.h"

namespace ts::scene {

// A grain type: `[grain]` (the only type) or one of the `[[grain]]` tables.
struct GrainSpec {
  std::string name;      // required when there are several types; "" for a lone unnamed type
  double radius = 1e-3;  // m, each of the four spheres
  double edge = 2e-3;    // m, sphere centre distance (default 2 radius: touching spheres)
  std::uint16_t material = 0;
  int line = 0;
};

// An emitter's grain size distribution: a dimensionless scale on its grain types (radius and edge
// together, so the shape stays), drawn per grain (scene/grain_mix.h).
enum class SizeDistribution {
  None,       // every grain at scale 1
  Uniform,    // scale uniform in [min, max], by number
  Lognormal,  // ln scale normal (median, sigma), redrawn outside [min, max]
  Sieve,      // classes (scale, mass fraction): the grains of each class weigh that share of the total
};
struct SizeSpec {
  SizeDistribution distribution = SizeDistribution::None;
  double min = 1, max = 1;       // uniform bounds; lognormal truncation (default median e^(-+3 sigma))
  double median = 1, sigma = 0;  // lognormal
  std::vector<std::pair<double, double>> sieve;  // (scale, mass fraction); fractions sum to 1
};

enum class EmitterType {
  Fill,    // `count` grains on a jittered lattice filling the box [min, max] at t = 0
  Pour,    // `count` grains released from the box [min, max] at `rate` grains/s from `start`
  Column,  // `count` grains stacked in a vertical cylinder (centre = base centre, radius) at t = 0
};

struct Emitter {
  EmitterType type = EmitterType::Fill;
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();  // m (fill, pour)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // m, column base centre
  double radius = 0;                                 // m, column radius
  std::size_t count = 0;                             // grains
  double rate = 0;                                   // grains/s (pour)
  double start = 0;                                  // s (pour)
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s, initial velocity of every grain
  std::uint64_t seed = 1;                              // jitter, orientations, types and sizes
  // Grain types (indices into Scene::grains) and their number fractions (sum 1): `grain` and
  // `fractions`; the counts are exact (largest remainder), the order shuffled.
  std::vector<std::uint16_t> grains{0};
  std::vector<double> fractions{1.0};
  SizeSpec size;
  int line = 0;  // where it was declared, for messages
};

// A `[[bond_material]]`: the parallel bonds of breakable props (sim/bond_model.h), named for `[[prop]]`
// bond_material and bind_material, with the seed of its bonds' strength draws.
struct BondMaterialSpec {
  std::string name;
  BondMaterial material;
  std::uint64_t seed = 1;  // strength_spread's draws (sim::build_bonds)
  int line = 0;
};

struct Prop {
  // `name`, or the body file without ".body.json" ("cube"): what follow = "prop NAME" and bind_to name.
  std::string name;
  std::filesystem::path body_file;  // NAME.body.json, resolved against the scene's folder
  // Pose of the mesh frame (the body file's coordinates): x_world = position + orientation * x_mesh.
  Eigen::Vector3d position = Eigen::Vector3d::Zero();              // m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // scene key: [w, x, y, z]
  MotionType motion = MotionType::Static;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          // m/s (kinematic: prescribed; dynamic: initial)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // rad/s, world frame
  std::uint16_t material = 0;
  // Kinematic props only: poses of the mesh frame over time (instead of velocity); empty = none.
  // Between keys the centre of mass moves on a straight line and the orientation slerps.
  std::vector<Keyframe> keyframes;
  // Kinematic props without keyframes only: a stress-controlled piston ([prop.servo], scene/servo.h)
  // that sets `velocity` as the run goes.
  std::optional<Servo> servo;
  // Breakable props (issue 48): the body's particles become one dynamic sphere body each, joined by the
  // bonds of Scene::bond_materials[bond_material]; with bind_to, the spheres within that material's
  // bond_distance of the spheres of prop bind_to are bound to them by bind_material's bonds.
  bool breakable = false;
  int bond_material = -1;  // index into Scene::bond_materials (breakable props)
  int bind_to = -1;        // index into Scene::props; -1: bound to nothing
  int bind_material = -1;  // index into Scene::bond_materials (with bind_to)
  std::size_t spheres = 0; // breakable props: the body's particle count, each a body of the world
  int line = 0;
};

// How many bodies of the world a prop is: one, or one per sphere of a breakable prop.
inline std::size_t prop_body_count(const Prop& p) { return p.breakable ? p.spheres : 1; }

enum class BoundaryType { Plane, Box, Cylinder };

struct Boundary {
  BoundaryType type = BoundaryType::Plane;
  bool rough = false;  // sampled as a static body of particles (thesis 4.4.4), else an implicit wall
  std::uint16_t material = 0;
  // plane: a point and the normal into the free side; rough planes cover `size` around `point`.
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();  // m, unit
  Eigen::Vector2d size = Eigen::Vector2d::Zero();  // m (rough plane extent along two in-plane axes)
  double hole_radius = 0;                          // m, a round hole around `point` (rough plane: an orifice)
  // How the hole's edge is made: false = the lattice with the spheres reaching into the hole left out
  // (a ragged edge: the opening is wider than 2 hole_radius); true = also lined by round_hole_rim.
  bool round_rim = false;
  // box: open top; grains stay inside [min, max].
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();  // m
  // cylinder: inside of a vertical wall.
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();  // m, (x, y)
  double radius = 0, z_min = 0, z_max = 0;         // m
  // rough sampling: particle radius and lattice spacing (default: touching particles).
  double particle_radius = 0;  // m
  double spacing = 0;          // m
  int line = 0;
};

struct SimulationSettings {
  double duration = 1.0;          // s
  double dt = 0;                  // s; 0 = "auto" (TimeStepBound::recommended)
  double max_impact_speed = 0;    // m/s for the contact-duration bound; 0 = from gravity and the scene height
  // Stop (exit 4) when velocity clamps do not die out: in two output intervals in a row at least one
  // clamp per step, the second interval with no fewer than the first (docs/reliability.md).
  bool check_clamps = true;
  // Refuse a dt by hand above kHandTimeStepFactor x the bound (sim/time_step.h); false: warn and run.
  bool check_time_step = true;
  // dt filled in by make_world. Scene files get symplectic Euler unless they ask for "euler": it meets
  // the 2 % restitution target at the automatic step, where forward Euler needs one about 20x smaller.
  StepSettings step{.integrator = Integrator::SemiImplicitEuler};
};

// How grains are coloured in the PNG frames ([output] color_by).
enum class FrameColoring {
  Sand,    // sand colours varied grain by grain; props steel blue
  Height,  // height of each sphere along +z, viridis from the grains' lowest to highest point
  Speed,   // speed of each sphere, viridis from 0 to the free-fall speed over the first frame's height
  Body,    // one colour per body (grains and props), hashed from its index; a breakable prop's
           // spheres one colour per fragment (the spheres its intact bonds still join)
};

// The camera of the PNG frames ([output.camera]). Without eye/target a default camera frames the
// walls and the grains at every frame (preview/sim_frames.h).
struct FrameCamera {
  std::optional<Eigen::Vector3d> eye, target;     // m, world; eye alone only when following a prop
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // image up (+z: the scene convention)
  double fov = 30.0;                              // degrees, vertical field of view
  int width = 960, height = 720;                  // pixels
  // follow = "prop NAME": the body of this [[prop]] (scene order) stays at the image centre; -1: "scene".
  // A breakable prop cannot be followed (it has no one centre once it breaks).
  int follow_prop = -1;
};

struct OutputSettings {
  std::int64_t every = 1000;  // steps between outputs
  bool frames = false;        // PNG frames through the preview renderer
  FrameColoring color_by = FrameColoring::Sand;
  bool walls = true;          // frames: draw the boundaries faintly
  FrameCamera camera;         // [output.camera]
  bool ply = false;           // particle positions per output
  bool vtp = false;           // VTK PolyData per output
  bool csv = true;            // metrics.csv: one row per output
  bool contacts = false;      // per-contact dump
  // Checkpoints (checkpoint_STEP.tsck in the output folder, docs/checkpoint-format.md): every this
  // many steps, and/or every this many seconds of wall-clock time; 0 = never.
  std::int64_t checkpoint_every = 0;  // steps
  double checkpoint_seconds = 0;      // s, wall clock
};

struct Scene {
  std::filesystem::path file;
  std::vector<Material> materials;
  std::vector<std::string> material_names;
  std::vector<GrainSpec> grains;             // `[grain]`, or the `[[grain]]` tables in file order
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};  // m/s^2
  std::vector<Emitter> emitters;
  std::vector<BondMaterialSpec> bond_materials;  // the `[[bond_material]]` tables in file order
  std::vector<Prop> props;
  std::vector<Boundary> boundaries;
  SimulationSettings simulation;
  OutputSettings output;
  // Line of each top-level, [simulation] and [output] key the file sets ("gravity", "simulation.dt"),
  // for messages about keys that are not read where they are checked.
  std::map<std::string, int, std::less<>> key_lines;

  bool has_bonds() const;  // a breakable prop: bonds in the world, the CPU reference's only for now
};

// "file:line: key" for messages, the line being `line`, or the key's line from Scene::key_lines when
// `line` is 0; without a line "file: key".
std::string scene_location(const Scene& scene, std::string_view key, int line = 0);

// Parses and validates a scene file. Throws ts::InputError naming file, line and key.
Scene load_scene(const std::filesystem::path& file);
// The same from text (`file` is only used in messages and to resolve relative paths).
Scene parse_scene(std::string_view text, const std::filesystem::path& file);

}  // namespace ts::scene
