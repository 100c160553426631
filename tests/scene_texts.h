#pragma once
// Scene texts shared by the test executables (sim and app tests): the smallest valid head, emitter
// tables, and a poured scene whose whole state changes as it runs (for checkpoint tests).
#include <fmt/format.h>

#include <string>

#include "tests/test_support.h"

namespace ts::test {

// A material and a grain, nothing else: the smallest scene that parses (12 lines).
inline constexpr const char* kMinimalScene = R"(# line 1
[[material]]
name = "sand"
E = 1.0e7
nu = 0.3
restitution = 0.65
mu = 0.5
density = 2600.0

[grain]
radius = 1.0e-3
material = "sand"
)";

// A soft material and coarse 5 mm grains of it (the scenes that run in the tests), 11 lines.
inline constexpr const char* kCoarseSand = R"([[material]]
name = "sand"
E = 1.0e6
nu = 0.3
restitution = 0.5
mu = 0.5
gamma_s = 2.0
density = 2600.0
[grain]
radius = 5.0e-3
material = "sand"
)";

// An [[emitter]] table of `type` ("fill" or "pour") over the box min..max (TOML arrays), `extra`
// keys after the count.
inline std::string box_emitter(const std::string& type, const std::string& min, const std::string& max,
                               long long count, const std::string& extra = "") {
  return fmt::format("[[emitter]]\ntype = \"{}\"\nmin = {}\nmax = {}\ncount = {}\n{}", type, min, max, count,
                     extra);
}

// A smooth [[boundary]] plane of sand through `point` with normal `normal` (TOML arrays).
inline std::string smooth_plane(const std::string& point, const std::string& normal) {
  return fmt::format("[[boundary]]\ntype = \"plane\"\npoint = {}\nnormal = {}\nmaterial = \"sand\"\n", point,
                     normal);
}

// What differs between the poured scenes of the tests.
struct PouredScene {
  int pour_count = 12;
  double pour_rate = 100.0;   // grains/s
  std::string pour_extra;     // more keys of the pour emitter
  double plate_time = 0.2;    // s, when the plate reaches plate_x
  double plate_x = -0.03;     // m
  std::string boundaries;     // [[boundary]] tables
  double duration = 0.12;     // s
  std::string simulation;     // more [simulation] keys
  int every = 100;            // [output] every (steps)
  int checkpoint_every = 37;  // steps
};

// 5 mm grains, a fill of 12 and a pour into it, a keyframed kinematic plate sweeping through and
// tangential springs: every part of the state a checkpoint keeps changes as the run goes.
inline std::string poured_scene(const PouredScene& p) {
  return fmt::format(R"(gravity = [0.0, 0.0, -9.81]
{}{}{}[[prop]]
body = "{}"
motion = "kinematic"
material = "sand"
[[prop.keyframes]]
time = 0.0
position = [-0.11, 0.0, 0.036]
orientation = [0.5, 0.5, 0.5, 0.5]
[[prop.keyframes]]
time = {}
position = [{}, 0.0, 0.036]
orientation = [0.5, 0.5, 0.5, 0.5]
{}[simulation]
duration = {}
integrator = "symplectic"
tangential = "spring"
{}
[output]
every = {}
ply = true
checkpoint_every = {}
)",
                     kCoarseSand,
                     box_emitter("fill", "[-0.045, -0.045, 0.006]", "[0.045, 0.045, 0.06]", 12, "seed = 5\n"),
                     box_emitter("pour", "[-0.03, -0.03, 0.08]", "[0.03, 0.03, 0.11]", p.pour_count,
                                 fmt::format("rate = {}\n{}seed = 9\n", p.pour_rate, p.pour_extra)),
                     asset("bodies/plate.body.json").string(), p.plate_time, p.plate_x, p.boundaries,
                     p.duration, p.simulation, p.every, p.checkpoint_every);
}

}  // namespace ts::test
