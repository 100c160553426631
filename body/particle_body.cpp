#include "body/particle_body.h"

namespace ts::body {

const char* mass_method_name(MassMethod method) {
  return method == MassMethod::WindingCells ? "winding_cells" : "closed_mesh";
}

void set_mass_properties(ParticleBody& body, const MassProperties& mass) {
  body.density = mass.density;
  body.volume = mass.volume;
  body.mass = mass.mass;
  body.center_of_mass = mass.center_of_mass;
  body.inertia = mass.inertia;
  body.principal_axes = mass.principal_axes;
  body.principal_moments = mass.principal_moments;
}

}  // namespace ts::body
