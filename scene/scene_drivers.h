#pragma once
// What changes a scene's world between two calls of its stepper, besides the stepper: the pour
// emitters releasing grains and the props' servos setting velocities. The scene runner and the Python
// Scene both step a world through this one object, so grains are released and servos updated at the
// same steps whoever drives the run (a stretch of steps ends where either acts next).
#include <cstdint>
#include <vector>

#include "scene/scene.h"
#include "scene/scene_world.h"
#include "scene/servo.h"
#include "sim/stepper.h"
#include "sim/world.h"

namespace ts::scene {

class SceneDrivers {
 public:
  // The pour emitters of `scene` and the servos of its props (bodies from `sources`), for time step dt (s).
  SceneDrivers(const Scene& scene, const WorldSources& sources, double dt);

  bool pouring() const;
  // Releases the grains each pour emitter owes by `world.time`; returns how many.
  std::size_t emit(World& world);
  // At the start of a stretch at `step`: releases due grains (not at step 0: the world was made with
  // the first release) and updates the servos due. True when the world changed, so the stepper must
  // load it again.
  bool act(World& world, Stepper& stepper, std::int64_t step);
  // Where a stretch of steps that starts at `step` ends: at the next output step (a multiple of the
  // scene's output.every), sooner while pouring (where the pours check again) or at the next servo
  // update. The runner acts and writes only at stretch ends, and a caller stepping the world in other
  // chunks acts at the same steps, so both give the same run.
  std::int64_t stretch_end(std::int64_t step) const;

  std::vector<PourEmitter>& pours() { return pours_; }
  const std::vector<PourEmitter>& pours() const { return pours_; }
  const ServoControl& servos() const { return servos_; }

 private:
  std::vector<PourEmitter> pours_;
  ServoControl servos_;
  std::int64_t output_every_ = 1;  // steps between outputs
  std::int64_t emit_every_ = 1;    // steps between pour checks: about twice per release
};

}  // namespace ts::scene
