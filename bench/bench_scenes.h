#pragma once
// Scenes shared by the benchmarks (defined once, like Box2D's shared/ folder). The scene files they
// start from live in assets/scenes/reference/ and are read by the tests and bench/peers too.
#include <cstdint>
#include <filesystem>
#include <string>

#include "sim/cpu_stepper.h"
#include "scene/scene.h"
#include "sim/world.h"

namespace ts::bench {

// <repo>/assets/scenes/reference/<name>; <repo> is $TETRASAND_SOURCE_DIR where set, else the build's source
// tree.
std::filesystem::path reference_scene(const std::string& name);

// `grains` tetrahedral grains (r = 1 mm, edge 2 mm, E = 10 MPa), randomly oriented on a lattice spaced
// 1.1 bounding diameters (no initial overlap), 4 layers deep in a box with a floor and four smooth side
// walls, falling under gravity: the workload of a pour that is settling.
sim::World settling_box(std::uint32_t grains, std::uint64_t seed);

// The dynamic bodies' centres as CSV "x_m,y_m,z_m" (the heap files that the Python reports measure).
std::string grain_centres_csv(const sim::World& world);

// A bonded FCC block of about `spheres` spheres (n^3 cells of 4, r = 1 mm, touching neighbours bonded:
// 12 bonds a sphere inside), each sphere its own body, resting on a floor plane under gravity, with
// bonds (E = 100 MPa) too strong to break: the steady cost of the bond law (issue 48). `dt` is the
// bonds' time-step bound (sim::bond_time_step).
struct BondedBlock {
  sim::World world;
  double dt = 0;  // s
};
BondedBlock bonded_block(std::uint32_t spheres);

// A world with the step settings it runs with (dt resolved from the scene).
struct BenchWorld {
  sim::World world;
  sim::StepSettings settings;
};

// `scene` built and run on the CPU reference for its [simulation] duration.
BenchWorld settle(const scene::Scene& scene);

// A resting bed of `grains` grains (rounded down to whole tiles, at least one): the tile
// reference/bed_tile.toml (1000 grains settled in a 5 cm box; settled once per process, about
// 20 s on two cores) copied side by side on a near-square grid, in one box of smooth walls around
// the whole. Each grain keeps the contacts it had in its tile, so every size is measured on the same
// per-grain contact load.
BenchWorld settled_bed(std::uint32_t grains);

// A scene that moves, for the cost of the contact lists' builds (issue 44, item 6): the settled bed of
// `grains` grains with a plough blade driven through it. The blade is a wall of kinematic spheres (each
// its own body, of the grains' particle radius so the grid's cell stays the bed's) spanning the bed's
// width, from just above the floor to 2 mm above the bed's top, moving along +x at `speed` (m/s); it
// stands in a slot cut across the bed a quarter of its length in (the grains it would overlap are left
// out), so it pushes grains from its first step. The step settings are the bed's, with the design
// speed (which picks the lists' skin) at least `speed`. `grains` counts the bed before the cut.
BenchWorld ploughed_bed(std::uint32_t grains, double speed);

}  // namespace ts::bench
