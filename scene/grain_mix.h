#pragma once
// Which grain type and size each grain of an emitter gets (issue 18: grain types and size
// distributions). A grain of type t at scale s is the type's tetrahedron with radius and edge both
// multiplied by s (the same shape, s^3 the mass). Draws come from the emitter's seed through their
// own generator, so the lattice jitter and the orientations (drawn from the seed as before) are
// unchanged and a scene with one type and no `size` places exactly the grains it did.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "sim/grain.h"
#include "scene/scene.h"
#include "scene/uses_engine.h"

namespace ts::scene {

struct GrainDraw {
  std::uint16_t type = 0;  // index into Scene::grains
  double scale = 1;        // dimensionless
};

// The type and scale of each of the emitter's `count` grains, in release order. Type counts are
// exact (the fractions times count, rounded by largest remainder), as are sieve class counts
// within each type (a class of mass fraction w at scale s has a number share ~ w / s^3); the order
// is then shuffled. Uniform and lognormal scales are drawn per grain. Same emitter, same draws, on
// every platform (the generator's own integer output only).
std::vector<GrainDraw> emitter_grain_draws(const Emitter& emitter);

// The smallest and largest scale an emitter's size distribution gives.
std::pair<double, double> scale_range(const SizeSpec& size);

// The tetrahedron of grain type `type` at `scale`.
GrainShape scaled_grain(const Scene& scene, std::uint16_t type, double scale);

// The bounding radius (m) of the emitter's largest possible grain: its lattice is spaced for it.
double emitter_bound(const Scene& scene, const Emitter& emitter);

// A kind of grain the scene holds at the edge of its size range: each type used by an emitter at
// the smallest and at the largest scale the emitters give it (scale 1 for every type when there are
// no emitters). The time-step bound takes its cases from these.
struct GrainKind {
  std::uint16_t type = 0;
  double scale = 1;
  GrainShape shape;
  std::string name;  // "a grain", "a grain of type \"fine\" at scale 0.8", for messages
};
std::vector<GrainKind> scene_grain_kinds(const Scene& scene);

}  // namespace ts::scene
