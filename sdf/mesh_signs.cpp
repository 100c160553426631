#include "sdf/mesh_signs.h"

#include "core/log.h"
#include "core/mesh_report.h"

namespace ts::sdf {

void warn_about_signs(const TriangleMesh& mesh, const std::string& name, SignMethod sign) {
  ReportOptions report_options;
  report_options.self_intersections = false;  // signs only need closedness and orientation
  const MeshReport report = analyze_mesh(mesh, report_options);
  if (!report.closed() && sign != SignMethod::Winding) {
    log::warn("{}: the mesh is not closed ({}); pseudonormal signs may be wrong near the holes: use --sign winding",
              name, closed_solid_problems(report));
  }
  if (encloses_no_volume(report)) {
    log::warn("{}: the mesh {}: the field has no inside", name, closed_solid_problems(report));
  }
  if (is_inside_out(report)) {
    log::warn("{}: the mesh is inside out (negative volume): inside and outside are swapped", name);
  }
}

}  // namespace ts::sdf
