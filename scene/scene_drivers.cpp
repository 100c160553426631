#include "scene/scene_drivers.h"

#include <algorithm>
#include <cmath>

namespace ts::scene {

namespace {

ServoControl servos_of(const Scene& scene, const WorldSources& sources) {
  std::vector<Servo> servos;
  std::vector<std::uint32_t> bodies;
  for (std::size_t k = 0; k < scene.props.size(); ++k) {
    if (!scene.props[k].servo) continue;
    servos.push_back(*scene.props[k].servo);
    bodies.push_back(sources.prop_bodies[k]);
  }
  return ServoControl(std::move(servos), std::move(bodies));
}

}  // namespace

SceneDrivers::SceneDrivers(const Scene& scene, const WorldSources& sources, double dt)
    : servos_(servos_of(scene, sources)), output_every_(scene.output.every), emit_every_(scene.output.every) {
  for (const Emitter& e : scene.emitters) {
    if (e.type != EmitterType::Pour) continue;
    pours_.emplace_back(scene, e);
    emit_every_ = std::min(emit_every_, std::max<std::int64_t>(1, std::llround(0.5 / (e.rate * dt))));
  }
}

bool SceneDrivers::pouring() const {
  return std::any_of(pours_.begin(), pours_.end(), [](const PourEmitter& p) { return !p.finished(); });
}

std::size_t SceneDrivers::emit(World& world) {
  std::size_t added = 0;
  for (PourEmitter& p : pours_) added += p.emit(world);
  return added;
}

bool SceneDrivers::act(World& world, Stepper& stepper, std::int64_t step) {
  bool changed = step > 0 && pouring() && emit(world) > 0;
  // The servos measure the contacts of the state the last stretch brought back; on the GPU a servo's
  // new velocity goes up with the whole state again (the caller's load), at servo steps only.
  if (servos_.update(world, stepper, step)) changed = true;
  return changed;
}

std::int64_t SceneDrivers::stretch_end(std::int64_t step) const {
  std::int64_t end = (step / output_every_ + 1) * output_every_;
  if (pouring()) end = std::min(end, step + emit_every_);
  if (!servos_.empty()) end = std::min(end, step + servos_.steps_to_next(step));
  return end;
}

}  // namespace ts::scene
