#pragma once
// What `tetrasand preview` reads besides the SDF: particle files, with their radius.
#include <filesystem>
#include <string>

#include "preview/renderer.h"

namespace ts::preview {

struct LoadedParticles {
  Particles particles;
  std::string radius_source;  // "body.json", "--particle-radius", "estimated from spacing"
  // m: the radius the set was sampled for (body.json's, else estimated from the spacing), whatever
  // radius the impostors are drawn at: the unit of --color-by particle-distance, so a drawing radius
  // does not change what the colours say about coverage.
  double sampled_radius = 0.0;
};

// NAME.body.json (particles and radius), or a PLY of particle centres (the readers of body/). The
// drawing radius is `radius` when positive, else the sampled radius: that of the body.json (or of the
// NAME.body.json beside a NAME.particles.ply), else half the median nearest-neighbour distance.
// ts::InputError naming the file.
LoadedParticles load_particles(const std::filesystem::path& file, double radius = 0.0);

// Half the median nearest-neighbour distance [m] (touching spheres on an even sampling); 0 for fewer
// than two points.
double estimate_radius(const std::vector<Eigen::Vector3d>& points);

}  // namespace ts::preview
