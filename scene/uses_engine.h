#pragma once
// The scene layer is written in the engine's vocabulary (World, Stepper, Material, StepStats, ...): its
// files use the names of ts::sim unqualified, as if they were declared in ts::scene. The arrow runs one
// way only: nothing in sim/ includes a scene/ header.
namespace ts::sim {}
namespace ts::scene {
using namespace ts::sim;
}  // namespace ts::scene
