#pragma once
// What is wrong with a mesh, counted: the checks `tetrasand info` prints and that `sample` and `sdf`
// use to refuse or warn. Topology is computed on the welded, indexed mesh.
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

#include "core/mesh.h"

namespace ts {

struct MeshReport {
  std::size_t vertices = 0, triangles = 0;
  std::size_t non_finite_vertices = 0;
  std::size_t degenerate_triangles = 0;    // zero area (repeated or collinear vertices)
  std::size_t duplicate_triangles = 0;     // same three vertices as an earlier triangle
  std::size_t boundary_edges = 0;          // edges of one triangle: holes
  std::size_t boundary_loops = 0;
  std::size_t non_manifold_edges = 0;      // edges of three or more triangles
  std::size_t non_manifold_vertices = 0;   // vertices whose triangles form more than one fan
  std::size_t inconsistent_edges = 0;      // two triangles traverse a shared edge the same way
  std::size_t components = 0;              // connected through shared vertices
  std::size_t self_intersecting_pairs = 0;  // triangle pairs that cross (CGAL exact predicates)
  bool self_intersections_exact = true;    // false: degenerate triangles of non-manifold input not tested
  // Triangle pairs of a non-manifold soup whose boxes overlap, each tested exactly: the work of that
  // check (a repeated triangle is tested once, so copies add none). Not printed.
  std::size_t self_intersection_candidates = 0;
  double area = 0;                         // m^2
  double signed_volume = 0;                // m^3; negative: inside out
  Aabb box;
  int genus = -1;  // closed manifold, not all degenerate: summed over components; else -1

  bool closed() const { return boundary_edges == 0 && non_manifold_edges == 0; }
  bool manifold() const { return non_manifold_edges == 0 && non_manifold_vertices == 0; }
  // Closed, manifold, consistently oriented, outward, no self-intersections: safe for SDF signs by
  // pseudonormals and for mass properties.
  bool watertight() const {
    return closed() && manifold() && inconsistent_edges == 0 && self_intersecting_pairs == 0 && signed_volume > 0 &&
           non_finite_vertices == 0;
  }
};

struct ReportOptions {
  bool self_intersections = true;  // the costly check (seconds on ~100k triangles)
};

inline bool is_closed_manifold(const MeshReport& r) { return r.closed() && r.manifold(); }
inline bool is_watertight(const MeshReport& r) { return r.watertight(); }
// True exactly when compute_mass_properties (core/mass_properties.h) accepts the mesh: closed,
// consistently oriented, finite, enclosing a positive volume. Self-intersections are allowed there.
inline bool encloses_volume(const MeshReport& r) {
  const double size = r.box.valid() ? r.box.size().maxCoeff() : 0.0;
  return r.closed() && r.inconsistent_edges == 0 && r.non_finite_vertices == 0 &&
         r.signed_volume > 1e-12 * size * size * size;
}

// Closed, with a volume that is zero up to rounding (encloses_volume's threshold): every triangle
// degenerate (a point set, or lines), or flat. Such a mesh is neither a solid nor inside out.
inline bool encloses_no_volume(const MeshReport& r) {
  const double size = r.box.valid() ? r.box.size().maxCoeff() : 0.0;
  return r.closed() && !(std::abs(r.signed_volume) > 1e-12 * size * size * size);
}
// Closed and of negative volume beyond rounding: the triangles face inward.
inline bool is_inside_out(const MeshReport& r) {
  return r.closed() && r.signed_volume < 0 && !encloses_no_volume(r);
}

MeshReport analyze_mesh(const TriangleMesh& mesh, const ReportOptions& options = {});
// Human-readable, several lines; problems are flagged.
std::string format_report(const MeshReport& report);
nlohmann::json to_json(const MeshReport& report);
// One line naming what makes the mesh unusable as a closed solid, or empty.
std::string closed_solid_problems(const MeshReport& report);

}  // namespace ts
