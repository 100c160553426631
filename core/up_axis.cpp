#include "core/up_axis.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <vector>

namespace ts {

UpAxisHint up_axis_hint(const Aabb& box) {
  UpAxisHint hint;
  if (!box.valid()) return hint;
  hint.extent = box.size();
  std::array<int, 3> order{2, 1, 0};  // ties go to z, then y: the convention wins a tie
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return hint.extent[a] > hint.extent[b]; });
  hint.tallest = order[0];
  hint.runner_up = order[1];
  hint.ambiguous = hint.extent[order[0]] > 0 && hint.extent[order[1]] >= kAmbiguousRatio * hint.extent[order[0]];
  return hint;
}

char axis_name(int axis) { return "xyz"[axis]; }

namespace {

// `--up` for an axis, and the scene orientation [w, x, y, z] that turns that axis onto +z.
std::string up_option(int axis) { return axis == 0 ? "1,0,0" : axis == 1 ? "0,1,0" : "0,0,1"; }
std::string orientation_onto_z(int axis) {
  // +90 degrees about x takes +y to +z; -90 degrees about y takes +x to +z.
  return axis == 0 ? "[0.7071068, 0, -0.7071068, 0]" : axis == 1 ? "[0.7071068, 0.7071068, 0, 0]" : "[1, 0, 0, 0]";
}

}  // namespace

std::string up_axis_advice(const UpAxisHint& hint, const std::string& mesh_file) {
  if (hint.ambiguous) {
    // Every axis nearly as long as the tallest, z first: the convention's choice is the one to try first.
    std::vector<int> near;
    for (int axis : {2, 1, 0})
      if (hint.extent[axis] >= kAmbiguousRatio * hint.extent[hint.tallest]) near.push_back(axis);
    std::vector<std::string> names, looks;
    for (int axis : near) {
      names.push_back(std::string(1, axis_name(axis)));
      looks.push_back(fmt::format("`-o up_{}.png --up {}`", axis_name(axis), up_option(axis)));
    }
    return fmt::format(
        "ambiguous: its {} extents are within {:.0f} % of each other, so the box does not tell which way is up "
        "(tetrasand takes +z). Look with `tetrasand preview {}` and {}, and pass the upright one's --up to "
        "preview and sample",
        fmt::join(names, ", "), 100.0 * (1.0 - kAmbiguousRatio), mesh_file, fmt::join(looks, ", "));
  }
  if (hint.tallest == 2) return "stands on +z as tetrasand expects (the simulator's up): nothing to choose";
  return fmt::format(
      "tetrasand takes +z as up; if this mesh stands along +{} (the habit of many OBJ files), pass --up {} "
      "to preview and sample, and place it upright in a scene with [[prop]] orientation = {}",
      axis_name(hint.tallest), up_option(hint.tallest), orientation_onto_z(hint.tallest));
}

}  // namespace ts
