#include "core/mesh_report.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include "core/mass_properties.h"
#include "core/union_find.h"

namespace ts {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;

std::uint64_t key(std::uint32_t a, std::uint32_t b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
}

struct EdgeUse {
  std::uint32_t count = 0, forward = 0;  // forward: traversals from the smaller to the larger index
};

// Whether two triangles that share corners overlap beyond what they share, decided the way CGAL's
// self_intersections decides it for adjacent faces.
bool adjacent_pair_intersects(const std::vector<Point>& points, const std::array<std::uint32_t, 3>& ia,
                              const std::array<std::uint32_t, 3>& ib) {
  auto in = [](const std::array<std::uint32_t, 3>& t, std::uint32_t u) { return std::find(t.begin(), t.end(), u) != t.end(); };
  std::vector<std::uint32_t> common;
  std::uint32_t far_a = 0, far_b = 0;
  for (auto u : ia) (in(ib, u) ? common.push_back(u) : void(far_a = u));
  for (auto u : ib)
    if (!in(ia, u)) far_b = u;
  if (common.size() == 2) {
    // Sharing the edge pq, they overlap only when coplanar with both far corners on the same side.
    const Point &p = points[common[0]], &q = points[common[1]], &r = points[far_a], &s = points[far_b];
    return CGAL::orientation(p, q, r, s) == CGAL::COPLANAR && CGAL::coplanar_orientation(p, q, r, s) == CGAL::POSITIVE;
  }
  // Sharing one corner: they meet elsewhere only if an edge opposite it reaches the other triangle.
  auto opposite = [&](const std::array<std::uint32_t, 3>& t) {
    const std::size_t k = static_cast<std::size_t>(std::find(t.begin(), t.end(), common[0]) - t.begin());
    return Kernel::Segment_3(points[t[(k + 1) % 3]], points[t[(k + 2) % 3]]);
  };
  auto triangle = [&](const std::array<std::uint32_t, 3>& t) { return Kernel::Triangle_3(points[t[0]], points[t[1]], points[t[2]]); };
  return CGAL::do_intersect(opposite(ia), triangle(ib)) || CGAL::do_intersect(opposite(ib), triangle(ia));
}

// Triangle pairs that intersect, with CGAL's exact predicates. Manifold input goes through
// Surface_mesh and PMP::self_intersections; other input is tested as a soup with the same rules for
// pairs that share corners. Degenerate triangles (counted on their own) are skipped on the soup path.
// The first triangle of each set with the same three corners (in any order): a repeated triangle is
// counted as a duplicate, and testing each copy against the others made the box pass quadratic in the
// copies (a glTF instancing one cube 4000 times took 54 s; issue 46). Hashing: linear.
std::vector<std::size_t> distinct_triangles(const TriangleMesh& mesh) {
  struct CornersHash {
    std::size_t operator()(const std::array<std::uint32_t, 3>& t) const {
      return std::hash<std::uint64_t>()((std::uint64_t{t[0]} << 42) ^ (std::uint64_t{t[1]} << 21) ^ t[2]) ^
             std::hash<std::uint32_t>()(t[1]);
    }
  };
  std::unordered_set<std::array<std::uint32_t, 3>, CornersHash> seen;
  seen.reserve(mesh.triangle_count());
  std::vector<std::size_t> first;
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    auto sorted = mesh.triangles[f];
    std::sort(sorted.begin(), sorted.end());
    if (seen.insert(sorted).second) first.push_back(f);
  }
  return first;
}

std::size_t count_self_intersections(const TriangleMesh& mesh, bool manifold, bool& exact,
                                     std::size_t& candidates) {
  std::vector<Point> points;
  points.reserve(mesh.vertex_count());
  for (const auto& v : mesh.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(mesh.triangle_count());
  for (const auto& t : mesh.triangles) polygons.push_back({t[0], t[1], t[2]});
  namespace PMP = CGAL::Polygon_mesh_processing;
  if (manifold && PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    CGAL::Surface_mesh<Point> surface;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, surface);
    std::vector<std::pair<CGAL::Surface_mesh<Point>::Face_index, CGAL::Surface_mesh<Point>::Face_index>> pairs;
    PMP::self_intersections<CGAL::Parallel_if_available_tag>(surface, std::back_inserter(pairs));
    exact = true;
    return pairs.size();
  }
  exact = true;
  using Box = CGAL::Box_intersection_d::Box_with_handle_d<double, 3, std::size_t, CGAL::Box_intersection_d::ID_EXPLICIT>;
  std::vector<Box> boxes;
  for (const std::size_t f : distinct_triangles(mesh)) {
    const auto& t = mesh.triangles[f];
    if (CGAL::collinear(points[t[0]], points[t[1]], points[t[2]])) {
      exact = false;
      continue;
    }
    const auto bbox = points[t[0]].bbox() + points[t[1]].bbox() + points[t[2]].bbox();
    boxes.emplace_back(bbox, f);
  }
  std::size_t count = 0;
  CGAL::box_self_intersection_d<CGAL::Sequential_tag>(boxes.begin(), boxes.end(), [&](const Box& a, const Box& b) {
    ++candidates;
    const auto& ta = mesh.triangles[a.handle()];
    const auto& tb = mesh.triangles[b.handle()];
    std::size_t shared = 0;
    for (auto u : ta) shared += std::find(tb.begin(), tb.end(), u) != tb.end() ? 1 : 0;
    if (shared == 3) return;  // a repeated triangle (distinct_triangles leaves none out)
    const bool hit = shared == 0 ? CGAL::do_intersect(Kernel::Triangle_3(points[ta[0]], points[ta[1]], points[ta[2]]),
                                                      Kernel::Triangle_3(points[tb[0]], points[tb[1]], points[tb[2]]))
                                 : adjacent_pair_intersects(points, ta, tb);
    if (hit) ++count;
  });
  return count;
}

}  // namespace

MeshReport analyze_mesh(const TriangleMesh& mesh, const ReportOptions& options) {
  MeshReport r;
  r.vertices = mesh.vertex_count();
  r.triangles = mesh.triangle_count();
  for (const auto& v : mesh.vertices) r.non_finite_vertices += v.allFinite() ? 0 : 1;
  r.box = bounding_box(mesh);
  r.area = surface_area(mesh);
  r.signed_volume = signed_volume(mesh);
  const double diagonal = r.box.valid() ? r.box.size().norm() : 0.0;

  std::unordered_map<std::uint64_t, EdgeUse> edges;
  edges.reserve(3 * mesh.triangle_count());
  std::map<std::array<std::uint32_t, 3>, std::uint32_t> seen_faces;
  UnionFind components(mesh.vertex_count());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const double doubled_area = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || !(doubled_area > 1e-14 * diagonal * diagonal)) {
      ++r.degenerate_triangles;
    }
    auto sorted = t;
    std::sort(sorted.begin(), sorted.end());
    if (++seen_faces[sorted] > 1) ++r.duplicate_triangles;
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t u = t[static_cast<std::size_t>(e)], v = t[static_cast<std::size_t>((e + 1) % 3)];
      if (u == v) continue;
      EdgeUse& use = edges[key(u, v)];
      ++use.count;
      use.forward += u < v ? 1 : 0;
      components.unite(u, v);
    }
  }
  UnionFind loops(mesh.vertex_count());
  std::vector<char> on_boundary(mesh.vertex_count(), 0);
  for (const auto& [k, use] : edges) {
    if (use.count == 1) {
      ++r.boundary_edges;
      const auto u = static_cast<std::uint32_t>(k >> 32), v = static_cast<std::uint32_t>(k & 0xffffffffu);
      loops.unite(u, v);
      on_boundary[u] = on_boundary[v] = 1;
    } else if (use.count > 2) {
      ++r.non_manifold_edges;
    } else if (use.forward != 1) {
      ++r.inconsistent_edges;
    }
  }
  std::vector<char> used(mesh.vertex_count(), 0);
  for (const auto& t : mesh.triangles)
    for (auto v : t) used[v] = 1;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (used[v] && components.find(v) == v) ++r.components;
    if (on_boundary[v] && loops.find(v) == v) ++r.boundary_loops;
  }

  // A vertex is manifold when its triangles form one fan: link them through shared edges at v.
  // A triangle that repeats a vertex (degenerate, counted as such) is in that vertex's fan once.
  std::vector<std::vector<std::uint32_t>> around(mesh.vertex_count());
  for (std::uint32_t f = 0; f < mesh.triangle_count(); ++f) {
    const auto& t = mesh.triangles[f];
    for (int c = 0; c < 3; ++c) {
      if ((c > 0 && t[c] == t[0]) || (c == 2 && t[2] == t[1])) continue;
      around[t[c]].push_back(f);
    }
  }
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const auto& faces = around[v];
    if (faces.size() < 2) continue;
    UnionFind fan(faces.size());
    std::unordered_map<std::uint32_t, std::size_t> first_with_neighbour;
    for (std::size_t i = 0; i < faces.size(); ++i) {
      for (auto w : mesh.triangles[faces[i]]) {
        if (w == v) continue;
        auto [it, inserted] = first_with_neighbour.try_emplace(w, i);
        if (!inserted) fan.unite(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(it->second));
      }
    }
    std::size_t fans = 0;
    for (std::size_t i = 0; i < faces.size(); ++i) fans += fan.find(static_cast<std::uint32_t>(i)) == i ? 1 : 0;
    if (fans > 1) ++r.non_manifold_vertices;
  }

  // Euler: chi = V - E + F = sum over components of (2 - 2 g). Unused vertices are not part of it.
  if (r.closed() && r.manifold() && r.components > 0 && r.degenerate_triangles < r.triangles) {
    const auto used_vertices = static_cast<long long>(std::count(used.begin(), used.end(), 1));
    const long long chi = used_vertices - static_cast<long long>(edges.size()) + static_cast<long long>(r.triangles);
    r.genus = static_cast<int>((2 * static_cast<long long>(r.components) - chi) / 2);
  }
  if (options.self_intersections && r.non_finite_vertices == 0 && !mesh.empty()) {
    r.self_intersecting_pairs =
        count_self_intersections(mesh, r.manifold() && r.boundary_edges == 0 && r.degenerate_triangles == 0,
                                 r.self_intersections_exact, r.self_intersection_candidates);
  }
  return r;
}

namespace {

std::string no_volume(const MeshReport& r) {
  if (r.degenerate_triangles == r.triangles) {
    return fmt::format("encloses no volume: all {} triangles are degenerate (zero area)", r.triangles);
  }
  return "encloses no volume (zero volume: flat or folded onto itself)";
}

}  // namespace

std::string closed_solid_problems(const MeshReport& r) {
  std::vector<std::string> problems;
  if (r.non_finite_vertices) problems.push_back(fmt::format("{} non-finite vertices", r.non_finite_vertices));
  if (r.boundary_edges) problems.push_back(fmt::format("{} boundary edges in {} holes", r.boundary_edges, r.boundary_loops));
  if (r.non_manifold_edges) problems.push_back(fmt::format("{} non-manifold edges", r.non_manifold_edges));
  if (r.non_manifold_vertices) problems.push_back(fmt::format("{} non-manifold vertices", r.non_manifold_vertices));
  if (r.inconsistent_edges) problems.push_back(fmt::format("{} inconsistently oriented edges", r.inconsistent_edges));
  if (r.self_intersecting_pairs) problems.push_back(fmt::format("{} self-intersecting triangle pairs", r.self_intersecting_pairs));
  if (encloses_no_volume(r)) {
    problems.push_back(no_volume(r));
  } else if (is_inside_out(r)) {
    problems.push_back("inside out (negative volume)");
  }
  std::string out;
  for (const auto& p : problems) out += (out.empty() ? "" : ", ") + p;
  return out;
}

std::string format_report(const MeshReport& r) {
  auto flag = [](std::size_t n) { return n ? "  <-- problem" : ""; };
  std::string s;
  s += fmt::format("vertices              {}\n", r.vertices);
  s += fmt::format("triangles             {}\n", r.triangles);
  s += fmt::format("components            {}\n", r.components);
  s += fmt::format("bounding box          [{:.6g}, {:.6g}, {:.6g}] .. [{:.6g}, {:.6g}, {:.6g}] m\n", r.box.min.x(),
                   r.box.min.y(), r.box.min.z(), r.box.max.x(), r.box.max.y(), r.box.max.z());
  s += fmt::format("area                  {:.9g} m^2\n", r.area);
  s += fmt::format("signed volume         {:.9g} m^3{}\n", r.signed_volume,
                   encloses_no_volume(r) ? "  <-- encloses no volume"
                   : is_inside_out(r)    ? "  <-- inside out"
                                         : "");
  s += fmt::format("non-finite vertices   {}{}\n", r.non_finite_vertices, flag(r.non_finite_vertices));
  s += fmt::format("degenerate triangles  {}{}\n", r.degenerate_triangles, flag(r.degenerate_triangles));
  s += fmt::format("duplicate triangles   {}{}\n", r.duplicate_triangles, flag(r.duplicate_triangles));
  s += fmt::format("boundary edges        {} in {} holes{}\n", r.boundary_edges, r.boundary_loops, flag(r.boundary_edges));
  s += fmt::format("non-manifold edges    {}{}\n", r.non_manifold_edges, flag(r.non_manifold_edges));
  s += fmt::format("non-manifold vertices {}{}\n", r.non_manifold_vertices, flag(r.non_manifold_vertices));
  s += fmt::format("inconsistent edges    {}{}\n", r.inconsistent_edges, flag(r.inconsistent_edges));
  s += fmt::format("self-intersections    {}{}{}\n", r.self_intersecting_pairs,
                   r.self_intersections_exact ? "" : " (degenerate triangles not tested)", flag(r.self_intersecting_pairs));
  if (r.genus >= 0) s += fmt::format("genus                 {}\n", r.genus);
  s += fmt::format("watertight            {}\n", r.watertight() ? "yes" : "no: " + closed_solid_problems(r));
  return s;
}

nlohmann::json to_json(const MeshReport& r) {
  return nlohmann::json{
      {"vertices", r.vertices},
      {"triangles", r.triangles},
      {"components", r.components},
      {"bounding_box", {{"min", {r.box.min.x(), r.box.min.y(), r.box.min.z()}}, {"max", {r.box.max.x(), r.box.max.y(), r.box.max.z()}}}},
      {"area", r.area},
      {"signed_volume", r.signed_volume},
      {"non_finite_vertices", r.non_finite_vertices},
      {"degenerate_triangles", r.degenerate_triangles},
      {"duplicate_triangles", r.duplicate_triangles},
      {"boundary_edges", r.boundary_edges},
      {"boundary_loops", r.boundary_loops},
      {"non_manifold_edges", r.non_manifold_edges},
      {"non_manifold_vertices", r.non_manifold_vertices},
      {"inconsistent_edges", r.inconsistent_edges},
      {"self_intersecting_pairs", r.self_intersecting_pairs},
      {"self_intersections_exact", r.self_intersections_exact},
      {"genus", r.genus >= 0 ? nlohmann::json(r.genus) : nlohmann::json(nullptr)},
      {"closed", r.closed()},
      {"manifold", r.manifold()},
      {"watertight", r.watertight()},
  };
}

}  // namespace ts
