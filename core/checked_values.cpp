#include "core/checked_values.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace ts {
namespace {

// The norm of v computed without overflow or underflow: scaled by its largest component first.
double stable_norm(const Eigen::VectorXd& v) {
  const double scale = v.cwiseAbs().maxCoeff();
  if (!(scale > 0) || !std::isfinite(scale)) return scale;
  return scale * (v / scale).norm();
}

// Normalising v divides by sqrt(v . v): when v . v overflows (a component of 1e200) the quotient is
// zero, and when it underflows below double's normal range the quotient is no unit vector. Both are
// refused; the message gives the true norm (computed scaled) so the user sees which it was.
std::string normalisable_problem(const Eigen::VectorXd& v, const char* what) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) return fmt::format("{} must be finite (component {} is {})", what, i, v[i]);
  }
  const double squared = v.squaredNorm();
  if (std::isfinite(squared) && squared >= std::numeric_limits<double>::min()) return {};
  if (stable_norm(v) == 0) return fmt::format("{} must not be zero", what);
  return fmt::format(
      "{} has a norm of {:.3g}, outside what normalising can take (give components between "
      "1e-150 and 1e150, e.g. a unit {})",
      what, stable_norm(v), what);
}

}  // namespace

std::string Where::describe() const {
  std::string s = file;
  if (line > 0) s += fmt::format(":{}", line);
  if (!key.empty()) s += (s.empty() ? "" : ": ") + key;
  return s;
}

void refuse_value(const Where& where, const std::string& problem) {
  const std::string place = where.describe();
  throw InputError(place.empty() ? problem : place + ": " + problem);
}

std::string finite_problem(double value) {
  return std::isfinite(value) ? std::string() : fmt::format("must be finite (got {})", value);
}

std::string unit_vector_problem(const Eigen::Vector3d& v) { return normalisable_problem(v, "vector"); }

std::string quaternion_problem(const Eigen::Vector4d& wxyz) {
  return normalisable_problem(wxyz, "quaternion [w, x, y, z]");
}

double checked_finite(double value, const Where& where) {
  if (const std::string problem = finite_problem(value); !problem.empty()) refuse_value(where, problem);
  return value;
}

Eigen::Vector3d checked_unit_vector(const Eigen::Vector3d& v, const Where& where) {
  if (const std::string problem = unit_vector_problem(v); !problem.empty()) refuse_value(where, problem);
  return v.normalized();
}

Eigen::Quaterniond checked_quaternion(const Eigen::Vector4d& wxyz, const Where& where) {
  if (const std::string problem = quaternion_problem(wxyz); !problem.empty()) refuse_value(where, problem);
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized();
}

std::int64_t checked_step_count(double duration, double dt, const Where& where) {
  if (!(dt > 0) || !std::isfinite(dt))
    refuse_value(where, fmt::format("dt must be finite and > 0 (got {})", dt));
  if (!(duration > 0) || !std::isfinite(duration))
    refuse_value(where, fmt::format("the duration must be finite and > 0 (got {})", duration));
  // A dt longer than the run would still take one step and simulate past its end (or, beyond 1e9
  // times the duration, round to zero steps): not one whole step fits.
  if (dt > duration * (1 + 1e-9)) {
    refuse_value(where,
                 fmt::format("dt = {:.6g} s is longer than the whole run of {:.6g} s: not one step fits "
                             "(use a dt <= the duration, or dt = \"auto\")",
                             dt, duration));
  }
  const double steps = std::max(1.0, std::ceil(duration / dt - 1e-9));
  // An int64 step counter; 9e18 steps would run for centuries anyway.
  if (steps > 9e18) {
    refuse_value(where,
                 fmt::format("{:.3g} steps of {:.3g} s do not fit a step counter (use a larger dt or a "
                             "shorter duration)",
                             steps, dt));
  }
  return static_cast<std::int64_t>(steps);
}

Eigen::Vector3d checked_position(const Eigen::Vector3d& p, double bound, const Where& where) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(p[i]) || std::abs(p[i]) > bound) {
      refuse_value(where,
                   fmt::format("position [{}, {}, {}] lies beyond the supported {:.3g} m from the origin on "
                               "an axis (move it within +-{:.3g} m)",
                               p.x(), p.y(), p.z(), bound, bound));
    }
  }
  return p;
}

Eigen::Vector3d checked_velocity(const Eigen::Vector3d& v, const Where& where) {
  for (int i = 0; i < 3; ++i) checked_finite(v[i], where);
  const double speed = stable_norm(v);
  if (speed > kMaxSpeed) {
    refuse_value(where, fmt::format("a speed of {:.3g} m/s exceeds the speed of light ({:.0f} m/s), and the "
                                    "kinetic energy it carries overflows (give a speed below it)",
                                    speed, kMaxSpeed));
  }
  return v;
}

}  // namespace ts
