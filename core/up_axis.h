#pragma once
// The one up convention of the tool (docs/architecture.md, "Axes"): +z is up, as in the simulator's
// world (gravity along -z). Meshes keep their own axes; what a mesh file means by up is a guess, so
// `info` reports the axis the mesh is tallest along and says how to choose when that guess is weak.
#include <string>

#include "core/mesh.h"

namespace ts {

struct UpAxisHint {
  int tallest = 2;    // 0, 1, 2 = x, y, z: the axis of the largest extent
  int runner_up = 1;  // the axis of the second largest extent
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();  // m, the bounding box's size
  // The runner-up extent is within kAmbiguousRatio of the tallest: a long animal lying along one axis
  // is as likely as a tall one standing on another, so the extents do not tell up.
  bool ambiguous = false;
};

inline constexpr double kAmbiguousRatio = 0.85;

// The hint for a bounding box (an empty or invalid box gives z, not ambiguous, zero extent).
UpAxisHint up_axis_hint(const Aabb& box);

// "x", "y" or "z".
char axis_name(int axis);

// What to do about it in one or two sentences: nothing when z is the tallest and clear; otherwise the
// --up option for preview and sample and the [[prop]] orientation that stands the mesh on +z in a
// scene, or (ambiguous) how to look before choosing.
std::string up_axis_advice(const UpAxisHint& hint, const std::string& mesh_file);

}  // namespace ts
