#pragma once
// Simulation state as plain data: structures of arrays indexed by body and by particle, so the GPU
// pipeline can upload each array as one buffer (positions as vec4, quaternions as vec4 xyzw...).
// Double precision here (the CPU reference); the GPU converts on upload.
//
// Frames: a body's position is its centre of mass in the world frame; its orientation rotates body
// coordinates into world coordinates (p_world = position + orientation * offset). Velocities are
// world-frame. Particles of one body are contiguous: [first_particle, first_particle + particle_count).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "sim/bonds.h"
#include "sim/contact_model.h"
#include "sim/grain.h"
#include "sim/keyframes.h"

namespace ts::sim {

enum class MotionType : std::uint8_t {
  Dynamic,    // integrated from forces
  Kinematic,  // moves with its prescribed velocity and angular velocity, or along a KinematicTrack;
              // forces do not affect it
  Static,     // never moves (floors, rough walls)
};

// |coordinate| / cell of any particle the engines can hold, the cell being the largest particle
// diameter: grid cells have 32-bit integer coordinates (the CPU grid clamps them at +-1e9, the GPU
// converts float to int). Scenes check it before their world is built (scene/scene_limits.h), bodies
// when read (body/body_file.h), checkpoints when read back (sim/world_bytes.h).
inline constexpr double kMaxCellCoordinate = 1e9;

struct Bodies {
  std::vector<Eigen::Vector3d> position;          // m, centre of mass
  std::vector<Eigen::Quaterniond> orientation;    // body -> world, unit
  std::vector<Eigen::Vector3d> linear_velocity;   // m/s
  std::vector<Eigen::Vector3d> angular_velocity;  // rad/s, world frame
  std::vector<double> inverse_mass;               // 1/kg; 0 for kinematic and static bodies
  std::vector<Eigen::Matrix3d> inverse_inertia;   // 1/(kg m^2), body frame; 0 for kinematic and static
  std::vector<double> bounding_radius;            // m: every particle sphere lies within it of position
  std::vector<MotionType> motion;
  std::vector<std::uint32_t> first_particle;
  std::vector<std::uint32_t> particle_count;

  std::size_t size() const { return position.size(); }
};

struct Particles {
  std::vector<std::uint32_t> body;        // owning body
  std::vector<Eigen::Vector3d> offset;    // m, body frame, from the body's centre of mass
  std::vector<double> radius;             // m
  std::vector<std::uint16_t> material;    // index into World::materials

  std::size_t size() const { return body.size(); }
};

// Smooth implicit walls (thesis 4.4.4 "implicit rigid bodies"): infinite mass, no particles.
// A half-space wall: particles stay on the side n . (x - point) >= 0.
struct PlaneWall {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // m, a point on the plane
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, into the free side
  std::uint16_t material = 0;

  bool operator==(const PlaneWall&) const = default;
};

// The inside of a vertical (z-axis) cylinder wall between z_min and z_max; outside that range of
// heights it does not act (particles can fall out of an open-bottomed silo).
struct CylinderWall {
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();  // m, (x, y) of the axis
  double radius = 1;                               // m
  double z_min = -1e30, z_max = 1e30;              // m
  std::uint16_t material = 0;

  bool operator==(const CylinderWall&) const = default;
};

struct Walls {
  std::vector<PlaneWall> planes;
  std::vector<CylinderWall> cylinders;
};

// Tangential springs of the contacts (TangentialModel::Spring only): kSpringSlots per particle, each
// the partner (particle id, or -1 - wall index; kNoPartner when free) and the elastic tangential
// displacement (m). Particle ids are stable (grains are only appended), so the springs survive
// emitters adding grains. Empty until a spring step runs.
struct ContactSprings {
  static constexpr std::size_t kSlots = 12;
  static constexpr std::int64_t kNoPartner = std::numeric_limits<std::int64_t>::max();
  std::vector<std::int64_t> partner;          // particles * kSlots
  std::vector<Eigen::Vector3d> displacement;  // m, particles * kSlots
};

struct World {
  Bodies bodies;
  Particles particles;
  ContactSprings springs;
  Walls walls;                               // rough walls are static bodies made of particles
  std::vector<KinematicTrack> tracks;        // keyframed kinematic bodies
  std::vector<Material> materials;
  // Breakable props (issue 48): the bonds between their spheres, indexed by particle, and the bond
  // materials they name (BondSet::material). Empty in a scene without breakable props.
  BondSet bonds;
  std::vector<BondMaterial> bond_materials;
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};  // m/s^2
  double time = 0;                           // s
};

// Appends a body made of the given particles (offsets relative to its centre of mass, body frame)
// and returns its index. inverse_inertia is body-frame; both inverse quantities are ignored (set
// to 0) unless motion is Dynamic.
struct BodyDesc {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  double inverse_mass = 0;                                     // 1/kg
  Eigen::Matrix3d inverse_inertia = Eigen::Matrix3d::Zero();  // 1/(kg m^2), body frame
  MotionType motion = MotionType::Dynamic;
};
std::uint32_t add_body(World& world, const BodyDesc& body, const std::vector<Eigen::Vector3d>& offsets,
                       const std::vector<double>& radii, std::uint16_t material);

// Appends a dynamic tetrahedral grain.
std::uint32_t add_grain(World& world, const GrainShape& grain, std::uint16_t material,
                        const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation,
                        const Eigen::Vector3d& linear_velocity = Eigen::Vector3d::Zero(),
                        const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero());

// Each tetrahedral grain (a dynamic body of four particles) becomes one solid sphere of the same
// volume and mass (radius 4^(1/3) r: the grain counts four whole spheres) at its centre of mass, so
// a run can contrast grain shape with everything else equal (the oedometer's and the silo's sphere
// runs); the other bodies keep their particles, in the same order. Contact springs are cleared.
void grains_to_spheres(World& world);

// The world without the particles `keep` rejects (called with the particle index): a static or
// kinematic body keeps the rest of its particles, or goes when none is left; a dynamic body is
// kept or dropped whole (its mass and inertia belong to all of its particles), by its first
// particle. For handing a state to another code without what was parked out of play (grains and
// plate particles moved far below a silo). Contact springs are cleared.
World without_particles(const World& world, const std::function<bool(std::size_t)>& keep);

// Sets every tracked body's pose and velocities to its track's at `time` (s).
void apply_tracks(World& world, double time);

// World position of every particle (m).
std::vector<Eigen::Vector3d> particle_positions(const World& world);

// Energies of the dynamic bodies (J). Potential energy is -m g . x (zero at the world origin).
struct Energy {
  double translational = 0, rotational = 0, potential = 0;
  double total() const { return translational + rotational + potential; }
};
Energy energy(const World& world);

// c when a body-frame inverse inertia is c times the identity (every grain: make_tetrahedral_grain's
// inertia is isotropic), else 0. Such a body's world-frame tensor is c Id in every orientation
// (R c Id R^T = c Id), so the integration and the energy need neither its rotation nor an inverse.
double isotropic_inverse_inertia(const Eigen::Matrix3d& inverse_inertia);

// Total linear momentum (kg m/s) and angular momentum about the origin (kg m^2/s) of dynamic bodies.
Eigen::Vector3d linear_momentum(const World& world);
Eigen::Vector3d angular_momentum(const World& world);

}  // namespace ts::sim
