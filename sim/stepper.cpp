#include "sim/stepper.h"

#include <fmt/format.h>

namespace ts::sim {

namespace {

std::string penetration_message(double time, const Penetration& p) {
  return fmt::format(
      "simulation unstable at t = {:.6g} s: particle {} has passed through smooth wall {} (its "
      "sphere is wholly behind the wall's surface; {} such particle-steps)",
      time, p.particle, p.wall, p.count);
}

}  // namespace

WallPenetration::WallPenetration(double time, const Penetration& penetration)
    : Error(ExitCode::Unstable, penetration_message(time, penetration)),
      time_(time),
      penetration_(penetration) {}

}  // namespace ts::sim
