#pragma once
// A particle rigid body as `tetrasand sample` writes it: NAME.particles.ply (one vertex per particle:
// float x y z nx ny nz, mesh coordinates) and NAME.body.json (radius, mass properties, provenance,
// sampling quality). docs/body-format.md is the schema; these functions are its one implementation.
#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/mass_properties.h"

namespace ts::sampler {

// Version 2 added interior_particle_count, mass_properties_method and mass_properties_cell; version
// 1 files are still read (surface particles only, mass properties from the closed mesh).
inline constexpr int kBodyFormatVersion = 2;

// Where a body's mass properties come from (body.json `mass_properties_method`).
enum class MassMethod {
  ClosedMesh,    // "closed_mesh": divergence theorem over the closed mesh, exact to rounding
  WindingCells,  // "winding_cells": octree integration over the winding-number solid (open meshes)
};
const char* mass_method_name(MassMethod method);

struct ParticleBody {
  std::vector<Eigen::Vector3f> positions;  // m, mesh coordinates (they overlay the mesh)
  std::vector<Eigen::Vector3f> normals;    // unit outward surface normals, one per particle, or none
  std::size_t interior_count = 0;          // the last ones are interior particles (--fill), normal (0, 0, 0)
  double particle_radius = 0.0;            // m
  double density = 0.0;                    // kg/m^3, of the solid the mesh encloses
  double mass = 0.0;                       // kg
  double volume = 0.0;                     // m^3
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();      // m, mesh coordinates
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();             // kg m^2, about the centre of mass, mesh axes
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();  // columns: unit axes in mesh coordinates
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();   // kg m^2, moment k about column k
  MassMethod mass_method = MassMethod::ClosedMesh;
  double mass_cell = 0.0;                  // m, finest octree cell of MassMethod::WindingCells (else 0)
  double sdf_voxel_size = 0.0;             // m, of the field the particles were relaxed on
  std::string source_path;                 // the mesh file, as given on the command line
  std::string source_sha256;               // lowercase hex SHA-256 of its bytes

  struct Quality {
    double relative_radius = 0.0;   // rho = min nearest-neighbour distance / d_hex
    double cv = 0.0;                // coefficient of variation of nearest-neighbour distances
    double covering_radius = 0.0;   // m, largest distance from the surface to a particle centre
    double covering_over_r = 0.0;   // covering_radius / particle_radius (<= 1: no gaps at all)
    std::optional<double> covering_over_r_plus_grain;  // c / (r + r_grain) when a grain radius was given
    double max_abs_phi_over_r = 0.0;  // largest particle distance from the surface / particle_radius
    int iterations = 0;             // relaxation steps, all rounds
    double seconds = 0.0;           // s, wall time of the sampler
    bool converged = false;
    int injection_rounds = 0;       // hole-closing rounds
  } quality;
};

// Copies density, volume, mass, centre of mass, inertia and principal frame from the mesh's solid.
void set_mass_properties(ParticleBody& body, const MassProperties& mass);

struct ParticlesPly {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;  // empty when the file has no nx ny nz
};

// Binary little-endian PLY, float x y z (and nx ny nz when `normals` is not empty; then it must match
// `positions` in size), written atomically.
void write_particles_ply(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& positions,
                         const std::vector<Eigen::Vector3f>& normals);

// Reads binary little-endian or ASCII PLY (hand-made files): the vertex element's x y z (required) and
// nx ny nz (all three or none), of any numeric type; other properties and elements are skipped.
// Throws ts::InputError naming the file: not a PLY, unsupported format, missing properties,
// truncated data, non-finite values.
ParticlesPly read_particles_ply(const std::filesystem::path& path);

// Writes DIR/NAME.particles.ply, then DIR/NAME.body.json, each atomically, the JSON staged in its
// temporary file before the PLY is replaced: a failure leaves a previous pair whole, and a reader
// that finds the JSON always finds the PLY it names. Creates DIR. Returns the JSON's path.
std::filesystem::path write_body(const std::filesystem::path& dir, const std::string& name, const ParticleBody& body);

// Reads and validates NAME.body.json and the PLY it names. Errors are ts::InputError
// "FILE: KEY: problem" (the key path, e.g. quality.cv); unknown keys are rejected.
ParticleBody read_body(const std::filesystem::path& json);

}  // namespace ts::sampler
