#pragma once
// Keyframed motion of kinematic bodies: a body's centre of mass moves on straight lines between
// keys at constant velocity and its orientation turns at a constant angular velocity (slerp, the
// shorter way round), so the velocities a contact sees are exactly the derivatives of the pose.
// Before the first key the body holds the first pose, after the last it holds the last (velocity 0).
// The GPU evaluates the same formulas (shaders/sim/keyframes.glsl).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace ts::sim {

struct Keyframe {
  double time = 0;                                                   // s, strictly increasing
  Eigen::Vector3d position = Eigen::Vector3d::Zero();                // m, centre of mass (world)
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // body -> world, unit
};

// The keys one kinematic body follows.
struct KinematicTrack {
  std::uint32_t body = 0;
  std::vector<Keyframe> keys;  // at least one
};

struct KinematicState {
  Eigen::Vector3d position, linear_velocity, angular_velocity;  // m, m/s, rad/s (world frame)
  Eigen::Quaterniond orientation;
};

// The pose and velocities at `time` (s). At a key's time the segment that starts there applies.
KinematicState sample_track(const std::vector<Keyframe>& keys, double time);

}  // namespace ts::sim
