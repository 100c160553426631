#include "sim/keyframes.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace ts::sim {

KinematicState sample_track(const std::vector<Keyframe>& keys, double time) {
  assert(!keys.empty());
  KinematicState out;
  out.linear_velocity.setZero();
  out.angular_velocity.setZero();
  if (time < keys.front().time || time >= keys.back().time || keys.size() == 1) {
    const Keyframe& hold = time < keys.front().time ? keys.front() : keys.back();
    out.position = hold.position;
    out.orientation = hold.orientation;
    return out;
  }
  // The segment [a, b) holding `time`: the last key at or before it.
  const auto after = std::upper_bound(keys.begin(), keys.end(), time,
                                      [](double t, const Keyframe& k) { return t < k.time; });
  const Keyframe& a = *(after - 1);
  const Keyframe& b = *after;
  const double span = b.time - a.time;  // s
  const double u = (time - a.time) / span;
  out.linear_velocity = (b.position - a.position) / span;
  out.position = a.position + u * (b.position - a.position);
  // The world-frame turn from a to b, the shorter way: angle theta about `axis`.
  Eigen::Quaterniond turn = b.orientation * a.orientation.conjugate();
  if (turn.w() < 0) turn.coeffs() = -turn.coeffs();
  const double s = turn.vec().norm();
  const double theta = 2.0 * std::atan2(s, turn.w());  // rad
  const Eigen::Vector3d axis = s > 0 ? Eigen::Vector3d(turn.vec() / s) : Eigen::Vector3d::UnitZ();
  out.angular_velocity = axis * (theta / span);
  const Eigen::Quaterniond partial(Eigen::AngleAxisd(u * theta, axis));
  out.orientation = (partial * a.orientation).normalized();
  return out;
}

}  // namespace ts::sim
