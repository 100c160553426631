#pragma once
// A run's checks against its contact model (docs/reliability.md, "Criteria"). Before the first step:
// a weight no contact can hold, and (dt = "auto") an impact the step cannot resolve, both exit 1
// naming file:line:key. During the run: velocity clamps that do not die out (exit 4), and the
// scene's names for a wall penetration found by an engine (sim/stepper.h, WallPenetration).
#include <cstddef>
#include <cstdint>
#include <string>

#include "scene/scene.h"
#include "scene/scene_world.h"
#include "sim/stepper.h"
#include "sim/world.h"
#include "scene/uses_engine.h"

namespace ts::scene {

// Throws ts::InputError when |g| presses a grain resting on any partner (another grain, a boundary,
// a body) past the overlap clamp, or, with the automatic time step `dt` (s), when the design impact
// speed moves a grain farther than the CFL distance in one step. Each message gives what would fit.
void check_scene_forces(const Scene& scene, const World& world, const WorldSources& sources, double dt);

// Watches the velocity clamps of successive output intervals (criterion 4).
class ClampWatch {
 public:
  explicit ClampWatch(bool enabled) : enabled_(enabled) {}
  // After an output interval of `steps` steps that ended at `time` (s) with `clamps` velocity clamps
  // (linear + angular): throws ts::Error(ExitCode::Unstable) when it and the interval before each had
  // at least one clamp per step and it had no fewer than the one before.
  void interval(std::size_t clamps, std::int64_t steps, double time);

  // The previous interval, for checkpoints.
  struct State {
    std::size_t clamps = 0;
    bool saturated = false;  // at least one clamp per step
  };
  const State& state() const { return state_; }
  void restore(const State& state) { state_ = state; }

 private:
  bool enabled_;
  State state_;
};

// The state a stretch of steps ended in, checked as the engines check the state each step starts
// from: a dynamic particle wholly behind a smooth wall's surface (plane: n . (x - point) < -r;
// cylinder: between z_min and z_max and farther than radius + r from the axis). The engines see a
// step's result only when the next step starts, so without this the last step of a run could carry
// a grain through a wall unnoticed. Count 0: none.
Penetration find_wall_penetration(const World& world);

// The message for a wall penetration, naming the wall, the body and where the particle is in `world`.
std::string describe_penetration(const WallPenetration& penetration, const World& world,
                                 const WorldSources& sources);

}  // namespace ts::scene
