#pragma once
// Whether a mesh's field can have trustworthy signs, said before the field is built: `tetrasand sdf`
// and the Python module's sdf() warn alike (a field is still built; sample refuses such meshes instead,
// sampler::check_sample_mesh).
#include <string>

#include "core/mesh.h"
#include "sdf/settings.h"

namespace ts::sdf {

// Logs a warning naming `name` for a mesh that is not closed (pseudonormal signs may be wrong near its
// holes: winding signs are the remedy), encloses no volume (the field has no inside) or is inside out.
void warn_about_signs(const TriangleMesh& mesh, const std::string& name, SignMethod sign);

}  // namespace ts::sdf
