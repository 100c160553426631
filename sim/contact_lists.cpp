#include "sim/contact_lists.h"

#include <algorithm>
#include <cmath>

namespace ts::sim {

double choose_skin(double largest_diameter, double design_speed, double dt, double requested) {
  if (requested > 0) return requested;
  const double travel = 2 * std::max(design_speed, 0.0) * std::max(dt, 0.0) * kStepsPerListBuild;  // m
  const double wanted = std::isfinite(travel) ? travel : kMaxSkinRatio * largest_diameter;
  return std::clamp(wanted, kMinSkinRatio * largest_diameter, kMaxSkinRatio * largest_diameter);
}

}  // namespace ts::sim
