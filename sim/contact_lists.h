#pragma once
// Contact candidate lists with a skin (Verlet lists), the rule both engines share. Each particle
// keeps the partners whose surfaces were within `skin` of its own when the list was built; the list
// stays complete until some particle has moved more than skin / 2 since then (two particles closing
// on each other at that speed close at most `skin`), so the engines rebuild only then, and the hashed
// grid with it. A larger skin means longer-lived lists and more candidates to test each step: the
// rule below aims at about kStepsPerListBuild steps between builds at the scene's design speed, held
// between kMinSkinRatio and kMaxSkinRatio of the largest particle diameter.
#include <cstdint>

namespace ts::sim {

inline constexpr double kStepsPerListBuild = 20;  // aimed at, at the design speed
inline constexpr double kMinSkinRatio = 0.05;     // of the largest diameter: a settled bed
inline constexpr double kMaxSkinRatio = 0.5;      // past this, candidates grow faster than builds shrink

// m: the skin for particles of largest diameter `largest_diameter` (m) moving at up to
// `design_speed` (m/s; the scene's impact speed) with time step `dt` (s): 2 v dt kStepsPerListBuild,
// held to [kMinSkinRatio, kMaxSkinRatio] x the diameter. `requested` > 0 (m, the scene's
// simulation.skin) is taken as is.
double choose_skin(double largest_diameter, double design_speed, double dt, double requested = 0);

// Whether lists built with `skin` are stale once some particle has moved `max_displacement` (m)
// since they were built.
inline bool lists_need_rebuild(double max_displacement, double skin) { return 2 * max_displacement > skin; }

}  // namespace ts::sim
