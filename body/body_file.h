#pragma once
// A body on disk: NAME.body.json (radius, mass properties, provenance, sampling quality; the schema
// is docs/body-format.md) and the NAME.particles.ply it names (body/particles_ply.h).
#include <filesystem>
#include <string>

#include "body/particle_body.h"

namespace ts::body {

// How far from its centre of mass a body's particle may lie, in particle diameters: the simulator's
// grid reaches 1e9 cells of the largest particle diameter (sim/world.h kMaxCellCoordinate,
// which asserts the two agree), so a body any wider could never be placed. read_body refuses it.
inline constexpr double kMaxBodyReachInDiameters = 1e9;

// Which keys of body.json read_body requires.
enum class BodyKeys {
  // Every key of the file's format_version: a body as `tetrasand sample` writes it.
  All,
  // Only what the simulator needs: particle_radius, mass, center_of_mass, inertia and particles
  // (hand-written props). Every other key of the format is checked as in All when present (a nested
  // object such as quality then with all its keys); keys the format does not know are errors all the
  // same (a misspelt key never passes silently). Absent keys leave the ParticleBody defaults, and the
  // particles' normals are checked against interior_particle_count only when that key is present.
  Physical,
};

// Writes DIR/NAME.particles.ply and DIR/NAME.body.json (format version kBodyFormatVersion) as one
// whole, also when the process is killed (core/atomic_file.h write_files_atomically, with the hidden
// journal DIR/.NAME.body.json.journal): a reader finds the previous pair or the new one, never one
// of each, and what a killed writer left is completed or removed by the next write or read. Creates
// DIR. Throws ts::InputError naming the key of an invalid body (nothing is written then). Returns
// the JSON's path.
std::filesystem::path write_body(const std::filesystem::path& dir, const std::string& name,
                                 const ParticleBody& body);

// Reads and validates NAME.body.json (format versions 1 and 2) and the PLY it names. Whatever
// `keys`, a body has at least one particle, particle_count (when given) matches the PLY, and inertia
// is symmetric positive definite. Errors are ts::InputError "FILE: KEY: problem" (the key path, e.g.
// quality.cv). A replacement that a killed writer left pending is completed first; one under way in
// a live process is an InputError; a pair replaced while it is read is read again.
ParticleBody read_body(const std::filesystem::path& json, BodyKeys keys = BodyKeys::All);

}  // namespace ts::body
