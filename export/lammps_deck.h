#pragma once
// A LAMMPS input deck of a tetrasand scene, so a scene that outgrows one GPU runs on a cluster
// under LAMMPS with MPI (`mpirun -np 64 lmp -in in.tetrasand`). Written for the Debian 12 build
// (LAMMPS 29 Sep 2021, GRANULAR, RIGID and MOLECULE packages); see docs/validation.md for the
// side-by-side checks.
//
// What the deck holds (files in the output folder):
//   in.tetrasand     the input script, with a README-style header saying what maps exactly
//   data.tetrasand   every particle of the initial world (grains, props, rough walls) with its body
//   bodies.rigid     fix rigid/small infile: mass, centre of mass, world-frame inertia, velocity and
//                    angular momentum of every dynamic body, given explicitly (LAMMPS would
//                    otherwise sum the overlapping spheres' masses about their centres)
//   grain.mol        the grain template (four spheres, explicit mass, COM and inertia) used by
//                    fix deposit for pour emitters; with several grain types or sizes poured,
//                    grain1.mol, grain2.mol ...: one per type and size (sieve class or size bin),
//                    drawn by fix deposit's molfrac in the emitter's proportions
//
// The contact model is the same as tetrasand's (Tsuji damping): per pair of materials, LAMMPS
// `hertz/material` gets E = 2 E* with nu = 0 (so its E_eff equals tetrasand's mixed E*), and a
// restitution whose Tsuji polynomial alpha(e) equals tetrasand's calibrated damping strength, so
// the normal damping force is identical term for term; `limit_damping` clamps attraction as
// tetrasand does. What cannot be matched exactly is listed in LammpsDeck::approximations and in the
// header of in.tetrasand.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace ts::exporter {
// Written in the vocabulary of the scene layer and the engine (Scene, World, Material, ...).
using namespace ts::scene;
using namespace ts::sim;


struct LammpsDeck {
  std::filesystem::path input;       // DIR/in.tetrasand
  std::vector<std::filesystem::path> files;  // every file written
  double dt = 0;                     // s
  std::int64_t steps = 0;
  std::size_t dynamic_bodies = 0;    // rigid bodies in the data file (pour emitters add more)
  std::size_t frozen_particles = 0;  // particles of static/kinematic bodies (rough walls, props)
  std::vector<std::string> approximations;  // where LAMMPS does not do exactly what tetrasand does
};

// Writes the deck of `scene` into `dir` (created if missing; files replaced atomically). Throws
// ts::InputError naming the scene file and the feature for what LAMMPS cannot reproduce (thesis
// normal damping, angular damping, kinematic props that both translate and spin, ...).
LammpsDeck export_lammps(const Scene& scene, const std::filesystem::path& dir);

// How a state is run (export_lammps_state).
struct LammpsStateRun {
  double duration = 0;                  // s simulated from the state
  double dt = 0;                        // s; 0: the scene's automatic step for this state
  std::int64_t thermo_every = 0;        // steps between thermo lines; 0: the scene's [output] every
  std::int64_t dump_every = 0;          // steps between particles.dump frames; 0: none (final.dump only)
  std::vector<std::string> before_run;  // LAMMPS commands placed just before the first `run` (computes,
                                        // variables, a thermo_style that replaces the deck's)
};

// The deck of a state of `scene` (a world made by make_world(scene) and stepped or changed: an
// orifice cut, grains removed) in place of the scene's initial world, so LAMMPS continues what
// tetrasand started: positions, orientations, velocities and spins carry over (bodies.rigid holds
// the rigid bodies' momenta, the data file's Velocities section every atom's). The scene's
// emitters are not exported (the state holds the grains already released). Dynamic bodies of one
// centred sphere with a solid sphere's inertia (0.4 m r^2) become plain LAMMPS spheres (fix
// nve/sphere), since fix rigid/small refuses one-atom bodies; any other one-particle body is refused.
LammpsDeck export_lammps_state(const Scene& scene, const World& state, const LammpsStateRun& run,
                               const std::filesystem::path& dir);

// LAMMPS's Tsuji damping coefficient alpha(e) (pair_granular.cpp: a sixth-order polynomial in the
// restitution e), and its inverse on [0, 1] (alpha decreases from 1.2728 at e = 0 to ~0 at e = 1).
// The inverse throws ts::InputError when alpha is out of that range.
double lammps_tsuji_alpha(double restitution);
double lammps_restitution_for_alpha(double alpha);

}  // namespace ts::exporter
