#pragma once
// Mass properties of a closed triangle mesh of uniform density by the divergence theorem (Mirtich 1996;
// Eberly, "Polyhedral Mass Properties (Revisited)"), in double precision.
#include <Eigen/Core>

#include "core/mesh.h"

namespace ts {

struct MassProperties {
  double density = 0;                                       // kg/m^3
  double volume = 0;                                        // m^3
  double mass = 0;                                          // kg
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();  // m, mesh coordinates
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();        // kg m^2, about the centre of mass, mesh axes
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();  // kg m^2, ascending
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();  // columns: unit axes, right-handed
};

struct PrincipalFrame {
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();   // kg m^2, ascending
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns: unit axes, moment k about column k, right-handed
};

// Eigen-decomposition of a symmetric inertia tensor [kg m^2]; the third axis is flipped where the
// eigenvectors came out left-handed, so the axes are a rotation of the mesh axes.
PrincipalFrame principal_frame(const Eigen::Matrix3d& inertia);

// Volume integrals only (signed: negative for an inside-out mesh), no validation.
double signed_volume(const TriangleMesh& mesh);

// Throws ts::InputError for a non-positive density, or a volume <= 0 (open or inside-out mesh).
MassProperties compute_mass_properties(const TriangleMesh& mesh, double density);

}  // namespace ts
