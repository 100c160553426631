#pragma once
// The largest sizes a scene may ask for, and the checks that compare the sizes its keys imply with
// them before anything is allocated (docs/reliability.md, "Sizes checked before allocation"). Every
// size is computed in double from the keys, so no count overflows on the way.
#include <cstdint>
#include <vector>

#include "body/body_file.h"
#include "scene/lattice.h"
#include "scene/scene.h"
#include "sim/world.h"
#include "scene/uses_engine.h"

namespace ts::scene {

// Particles of a world: both engines' hashed grids have a table of the next power of two >= 2 N
// entries, indexed with 32 bits.
inline constexpr double kMaxParticles = 1073741824.0;  // 2^30
// sim::kMaxCellCoordinate (sim/world.h) bounds every place particles start at.
static_assert(kMaxCellCoordinate == body::kMaxBodyReachInDiameters, "a body readable is a body placeable");

// The sizes the scene's keys alone imply: each emitter's lattice and grain count, each rough
// boundary's particles, and their sum. Throws ts::InputError "file:line: key: ..." with the size asked
// for and the largest that fits.
void check_scene_sizes(const Scene& scene);

// Particles the emitters' grains and the rough boundaries imply (props apart), in double, before any
// is made: what a caller that wants only small runs (the fuzz targets) bounds a scene by.
double implied_particles(const Scene& scene);

// Once the boundaries and props are in `world` (and no grain yet): the whole world's particles with
// every emitter's grains, and the grid cell coordinates of every place particles start at (the cell
// is the largest particle diameter), a prop's particles included (`prop_bodies`: each prop's body in
// `world`, in scene order). Throws as check_scene_sizes.
void check_world_sizes(const Scene& scene, const World& world, const std::vector<std::uint32_t>& prop_bodies);

}  // namespace ts::scene
