#pragma once
// One value checker for every number a user or a file gives (a scene, a body, a checkpoint, the
// command line). A value passes only when it is finite, in its range, and still meaningful after the
// arithmetic it feeds: a vector's norm is computed without overflow before it is normalised, a step
// count is at least one. A refused value throws InputError naming where it came from (file, line,
// key), the value and what would work.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>

namespace ts {

// Where a value came from; line 0 when the source has no lines (a checkpoint's field, an option).
struct Where {
  std::string file;
  int line = 0;
  std::string key;

  std::string describe() const;  // "file:line: key", leaving out what is unknown
};

[[noreturn]] void refuse_value(const Where& where, const std::string& problem);

// Problems without throwing, for readers that report through their own channel ("" when fine).
std::string finite_problem(double value);
std::string unit_vector_problem(const Eigen::Vector3d& v);
std::string quaternion_problem(const Eigen::Vector4d& wxyz);

double checked_finite(double value, const Where& where);
// A direction: every component finite, and its norm finite and non-zero (1e200 overflows the norm
// and would normalise to zero; 1e-200 underflows it likewise).
Eigen::Vector3d checked_unit_vector(const Eigen::Vector3d& v, const Where& where);
// An orientation given as [w, x, y, z]: normalisable as above.
Eigen::Quaterniond checked_quaternion(const Eigen::Vector4d& wxyz, const Where& where);
// How many steps of dt cover duration: dt finite and > 0, and at least one step (a dt of inf, or one
// longer than the run, would take zero steps and report success).
std::int64_t checked_step_count(double duration, double dt, const Where& where);
// A point within `bound` m of the origin on every axis (the engine's grid coordinates are bounded).
Eigen::Vector3d checked_position(const Eigen::Vector3d& p, double bound, const Where& where);

// A velocity (m/s) no faster than light: a speed of 1e300 m/s is finite, but its kinetic energy
// overflows to inf in the first output. Any real scene is far below the bound.
inline constexpr double kMaxSpeed = 299792458.0;  // m/s
Eigen::Vector3d checked_velocity(const Eigen::Vector3d& v, const Where& where);

// A rigid body's mass (kg) or principal moment of inertia (kg m^2) the simulator can use: it inverts
// both (1/m, a 3x3 inverse whose determinant cubes the moments) and multiplies by squared speeds, so
// beyond 1e+-100 the arithmetic leaves double's range (density = 1e200 wrote a NaN energy).
inline constexpr double kLeastMass = 1e-100, kMostMass = 1e100;
inline bool mass_fits(double value) { return value >= kLeastMass && value <= kMostMass; }

}  // namespace ts
