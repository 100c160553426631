#pragma once
// A body on disk: NAME.body.json (radius, mass properties, provenance, sampling quality; the schema
// is docs/body-format.md) and the NAME.particles.ply it names (body/particles_ply.h).
#include <filesystem>
#include <string>

#include "body/particle_body.h"

namespace ts::body {

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

// Writes DIR/NAME.particles.ply, then DIR/NAME.body.json (format version kBodyFormatVersion), each
// atomically, the JSON staged in its temporary file before the PLY is replaced: a failure leaves a
// previous pair whole, and a reader that finds the JSON always finds the PLY it names. Creates DIR.
// Throws ts::InputError naming the key of an invalid body (nothing is written then). Returns the
// JSON's path.
std::filesystem::path write_body(const std::filesystem::path& dir, const std::string& name,
                                 const ParticleBody& body);

// Reads and validates NAME.body.json (format versions 1 and 2) and the PLY it names. Whatever
// `keys`, a body has at least one particle, particle_count (when given) matches the PLY, and inertia
// is symmetric positive definite. Errors are ts::InputError "FILE: KEY: problem" (the key path, e.g.
// quality.cv).
ParticleBody read_body(const std::filesystem::path& json, BodyKeys keys = BodyKeys::All);

}  // namespace ts::body
