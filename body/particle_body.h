#pragma once
// The particle rigid body that carries the sampler's output into the simulator and the previews:
// particles (centres and surface normals, mesh coordinates), their radius, the mass properties of the
// solid they stand for, and how it was made. body/body_file.h reads and writes it (NAME.body.json +
// NAME.particles.ply, schema in docs/body-format.md); this folder is the format's one implementation.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/mass_properties.h"

namespace ts::body {

// body.json `format_version` written. Version 2 added interior_particle_count,
// mass_properties_method and mass_properties_cell; version 3 the coverage certificate's figures in
// quality. Versions 1 and 2 are still read (version 1: surface particles only, mass properties from
// the closed mesh; both: no certificate).
inline constexpr int kBodyFormatVersion = 3;

// Where a body's mass properties come from (body.json `mass_properties_method`).
enum class MassMethod {
  ClosedMesh,    // "closed_mesh": divergence theorem over the closed mesh, exact to rounding
  WindingCells,  // "winding_cells": octree integration over the winding-number solid (open meshes)
};

// The method's name in body.json: "closed_mesh" or "winding_cells".
const char* mass_method_name(MassMethod method);

struct ParticleBody {
  std::vector<Eigen::Vector3f> positions;  // m, mesh coordinates (they overlay the mesh), as stored
  std::vector<Eigen::Vector3f> normals;    // unit outward surface normals, one per particle, or none
  std::size_t interior_count = 0;          // the last ones are interior particles (--fill), normal (0, 0, 0)
  double particle_radius = 0.0;            // m
  double density = 0.0;                    // kg/m^3, of the solid the mesh encloses
  double mass = 0.0;                       // kg
  double volume = 0.0;                     // m^3
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();  // m, mesh coordinates
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();         // kg m^2, about the centre of mass, mesh axes
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();  // columns: unit axes in mesh coordinates
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();   // kg m^2, moment k about column k
  MassMethod mass_method = MassMethod::ClosedMesh;
  double mass_cell = 0.0;       // m, finest octree cell of MassMethod::WindingCells (else 0)
  double sdf_voxel_size = 0.0;  // m, of the field the particles were relaxed on
  std::string source_path;      // the mesh file, as given on the command line
  std::string source_sha256;    // lowercase hex SHA-256 of its bytes

  struct Quality {
    double relative_radius = 0.0;  // rho = min nearest-neighbour distance / d_hex
    double cv = 0.0;               // coefficient of variation of nearest-neighbour distances
    double covering_radius = 0.0;  // m, largest distance from the surface to a particle centre
    double covering_over_r = 0.0;  // covering_radius / particle_radius (<= 1: no gaps at all)
    std::optional<double> covering_over_r_plus_grain;  // c / (r + r_grain) when a grain radius was given
    double max_abs_phi_over_r = 0.0;  // largest particle distance from the surface / particle_radius
    int iterations = 0;               // relaxation steps, all rounds
    double seconds = 0.0;             // s, wall time of the sampler
    bool converged = false;
    int injection_rounds = 0;  // hole-closing rounds

    // The coverage certificate of the surface particles at radius r (sampler/gpu_coverage_certificate.h,
    // docs/coverage-certificate.md): a proof, where covering_radius is a random sample's figure.
    struct Certificate {
      bool certified = false;                  // proven: every surface point lies within r of a centre
      double bound_over_r = 0.0;               // covering radius / r is at most this (certified)
      double lower_over_r = 0.0;               // and at least this (a point the certificate evaluated)
      std::size_t uncovered_subtriangles = 0;  // final sub-triangles not proven covered (0 iff certified)
      double uncovered_area = 0.0;             // m^2, their area (an upper bound of the uncovered area)
      double floor = 0.0;                      // m, longest edge below which no sub-triangle is split
    };
    // Format version 3; absent in older files and in bodies whose maker computed none.
    std::optional<Certificate> certificate;
  } quality;
};

// Copies density, volume, mass, centre of mass, inertia and principal frame from the mesh's solid.
void set_mass_properties(ParticleBody& body, const MassProperties& mass);

}  // namespace ts::body
