#pragma once
// What the body tests share: the keys of a test body beyond its particles and mass properties.
#include <string>

#include "body/particle_body.h"

namespace ts::test {

// Radius r [m], SDF voxel r / 4, a made-up source and sampling quality that pass the writer's checks.
inline void set_sampling_keys(body::ParticleBody& body, double radius) {
  body.particle_radius = radius;
  body.sdf_voxel_size = radius / 4.0;
  body.source_path = "meshes/box.obj";
  body.source_sha256 = std::string(64, 'a');
  body.quality = {0.81, 0.035, 0.047, 0.94, 0.47 / 1.5, 0.02, 1234, 1.75, true, 2,
                  body::ParticleBody::Quality::Certificate{false, 1.07, 1.02, 12, 3e-4, radius / 64.0}};
}

}  // namespace ts::test
