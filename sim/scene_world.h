#pragma once
// From a parsed scene (sim/scene.h) to the simulator's world (sim/world.h): materials, smooth walls,
// rough walls as static particle bodies, props from their body files, the grains of the emitters,
// and the time-step bound of the scene's contacts. Implemented in sim/scene_world.cpp.
#include <Eigen/Core>

#include <cstddef>
#include <random>
#include <vector>

#include "sim/grain.h"
#include "sim/scene.h"
#include "sim/time_step.h"
#include "sim/world.h"

namespace ts::sim {

// The initial world of a scene: materials, smooth walls, rough walls as static particle bodies,
// props, and the grains of the fill and column emitters. Pour emitters run through PourEmitter.
World make_world(const Scene& scene);

// The time-step bound for the scene's contact kinds (grain-grain, grain-wall, grain-prop).
TimeStepBound scene_time_step_bound(const Scene& scene, const World& world);

// Offsets from the hole's centre of fixed spheres of `radius` lining a round hole in a rough plane
// (in-plane axes t1, t2, normal n into the free side; sphere tops in the plane, as the lattice's):
// centres on a circle of hole_radius + radius, at most `radius` apart, so the opening is a disc of
// 2 hole_radius to within bumps of 0.14 radius (a lattice with the spheres reaching into the hole left
// out opens up to a spacing wider, unevenly).
std::vector<Eigen::Vector3d> round_hole_rim(const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                                            const Eigen::Vector3d& n, double hole_radius, double radius);

// Releases a pour emitter's grains as time passes, at free lattice sites of its region.
class PourEmitter {
 public:
  PourEmitter(const Scene& scene, const Emitter& emitter);
  // Adds the grains due by world.time whose site is free; returns how many were added.
  std::size_t emit(World& world);
  bool finished() const { return emitted_ == emitter_.count; }

 private:
  GrainShape grain_;
  Emitter emitter_;
  std::uint16_t material_;
  std::vector<Eigen::Vector3d> sites_;  // m, lattice sites of the region
  std::size_t next_site_ = 0, emitted_ = 0;
  std::mt19937_64 rng_;
};

// Lattice sites (m) for grains of bounding radius `bound` in a box: spacing >= 2.22 d so that
// no two grains overlap whatever their orientation (notes/peers.md), jittered by `rng`.
std::vector<Eigen::Vector3d> grain_sites_in_box(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double bound,
                                                std::mt19937_64& rng);

}  // namespace ts::sim
