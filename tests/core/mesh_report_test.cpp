#include "core/mesh_report.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "core/atomic_file.h"
#include "core/mesh_io.h"
#include "core/primitives.h"
#include "tests/test_support.h"

namespace ts {
namespace {

// A glTF whose `copies` nodes all place the same unit cube (8 positions, 12 triangles) at the origin.
std::string instanced_cube_gltf(int copies) {
  std::string nodes, roots;
  for (int i = 0; i < copies; ++i) {
    nodes += i ? ",{\"mesh\":0}" : "{\"mesh\":0}";
    roots += i ? "," : "";
    roots += std::to_string(i);
  }
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[)" + roots + R"(]}],"nodes":[)" + nodes +
         R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"accessors":[)"
         R"({"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},)"
         R"({"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}],)"
         R"("bufferViews":[{"buffer":0,"byteLength":96},{"buffer":0,"byteOffset":96,"byteLength":72}],)"
         R"("buffers":[{"byteLength":168,"uri":"data:application/octet-stream;base64,)"
         R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AACAPwAAAAAAAIA/)"
         R"(AACAPwAAgD8AAIA/AAAAAAAAgD8AAIA/AAACAAEAAAADAAIABAAFAAYABAAGAAcAAAABAAUAAAAFAAQAAQACAAYAAQAGAAUA)"
         R"(AgADAAcAAgAHAAYAAwAAAAQAAwAEAAcA"}]})";
}

TEST(MeshReport, GeneratedAssetsAreWatertightAndOutward) {
  for (const char* name : {"sphere.obj", "cube.obj", "torus.obj", "trefoil.obj", "plate.obj", "bunny.obj"}) {
    const MeshReport r = analyze_mesh(load_mesh(test::asset(name)));
    EXPECT_TRUE(r.watertight()) << name << "\n" << format_report(r);
    EXPECT_EQ(r.components, 1u) << name;
  }
  EXPECT_EQ(analyze_mesh(load_mesh(test::asset("torus.obj"))).genus, 1);
  EXPECT_EQ(analyze_mesh(load_mesh(test::asset("trefoil.obj"))).genus, 1);
  EXPECT_EQ(analyze_mesh(load_mesh(test::asset("bunny.obj"))).genus, 0);
}

TEST(MeshReport, OpenCubeHasOneHole) {
  TriangleMesh m = make_box({0, 0, 0}, {1, 1, 1});
  m.triangles.erase(m.triangles.begin(), m.triangles.begin() + 2);  // remove one face
  const MeshReport r = analyze_mesh(m);
  EXPECT_EQ(r.boundary_edges, 4u);
  EXPECT_EQ(r.boundary_loops, 1u);
  EXPECT_FALSE(r.closed());
  EXPECT_FALSE(closed_solid_problems(r).empty());
}

TEST(MeshReport, CountsDuplicateFlippedAndNonManifold) {
  TriangleMesh dup = make_box({0, 0, 0}, {1, 1, 1});
  dup.triangles.push_back(dup.triangles[0]);
  const MeshReport rd = analyze_mesh(dup);
  EXPECT_EQ(rd.duplicate_triangles, 1u);
  EXPECT_GT(rd.non_manifold_edges, 0u);

  TriangleMesh flipped = make_box({0, 0, 0}, {1, 1, 1});
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
  EXPECT_EQ(analyze_mesh(flipped).inconsistent_edges, 3u);

  TriangleMesh inside_out = make_box({0, 0, 0}, {1, 1, 1});
  for (auto& t : inside_out.triangles) std::swap(t[1], t[2]);
  const MeshReport ri = analyze_mesh(inside_out);
  EXPECT_LT(ri.signed_volume, 0.0);
  EXPECT_FALSE(ri.watertight());

  // Two cubes sharing one corner vertex: a non-manifold vertex, two components joined at it.
  TriangleMesh a = make_box({0, 0, 0}, {1, 1, 1}), b = make_box({1, 1, 1}, {2, 2, 2});
  const auto offset = static_cast<std::uint32_t>(a.vertices.size());
  for (auto& v : b.vertices) a.vertices.push_back(v);
  for (auto t : b.triangles) {
    for (auto& i : t) i = (b.vertices[i - 0] == Eigen::Vector3d(1, 1, 1)) ? 7u : i + offset;
    a.triangles.push_back(t);
  }
  EXPECT_EQ(analyze_mesh(a).non_manifold_vertices, 1u);
}

TEST(MeshReport, CountsComponentsAndDegenerateTriangles) {
  TriangleMesh two = make_box({0, 0, 0}, {1, 1, 1});
  const TriangleMesh other = make_box({3, 0, 0}, {4, 1, 1});
  const auto offset = static_cast<std::uint32_t>(two.vertices.size());
  for (auto& v : other.vertices) two.vertices.push_back(v);
  for (auto t : other.triangles) two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  two.triangles.push_back({0, 0, 1});
  const MeshReport r = analyze_mesh(two);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.degenerate_triangles, 1u);
}

TEST(MeshReport, ThreeIdenticalPointsAreDegenerateNotInsideOut) {
  TriangleMesh points;
  points.vertices = {{1, 1, 1}};
  points.triangles = {{0, 0, 0}};
  const MeshReport r = analyze_mesh(points);
  EXPECT_EQ(r.degenerate_triangles, 1u);
  EXPECT_EQ(r.non_manifold_vertices, 0u);  // one degenerate triangle is no fan of two
  EXPECT_TRUE(encloses_no_volume(r));
  EXPECT_FALSE(is_inside_out(r));
  EXPECT_EQ(closed_solid_problems(r), "encloses no volume: all 1 triangles are degenerate (zero area)");
  const std::string text = format_report(r);
  EXPECT_EQ(text.find("inside out"), std::string::npos) << text;
  EXPECT_NE(text.find("0 m^3  <-- encloses no volume"), std::string::npos) << text;
  // A box turned inside out still is.
  TriangleMesh flipped = make_box({0, 0, 0}, {1, 1, 1});
  for (auto& t : flipped.triangles) std::swap(t[1], t[2]);
  const MeshReport rf = analyze_mesh(flipped);
  EXPECT_TRUE(is_inside_out(rf));
  EXPECT_EQ(closed_solid_problems(rf), "inside out (negative volume)");
}

TEST(MeshReport, FindsASelfIntersectingPair) {
  TriangleMesh m = make_box({0, 0, 0}, {1, 1, 1});
  const TriangleMesh inner = make_box({0.5, 0.5, 0.5}, {1.5, 1.5, 1.5});  // overlapping second box
  const auto offset = static_cast<std::uint32_t>(m.vertices.size());
  for (auto& v : inner.vertices) m.vertices.push_back(v);
  for (auto t : inner.triangles) m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  EXPECT_GT(analyze_mesh(m).self_intersecting_pairs, 0u);
  EXPECT_EQ(analyze_mesh(make_box({0, 0, 0}, {1, 1, 1})).self_intersecting_pairs, 0u);
}

TEST(MeshReport, GenusIsSummedOverClosedComponents) {
  TriangleMesh two = make_torus(1.0, 0.3, 24, 8);
  const TriangleMesh sphere = make_icosphere(0.5, 1);
  const auto offset = static_cast<std::uint32_t>(two.vertices.size());
  for (const auto& v : sphere.vertices) two.vertices.push_back(v + Eigen::Vector3d(5, 0, 0));
  for (const auto& t : sphere.triangles) two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  two.vertices.push_back(Eigen::Vector3d(9, 9, 9));  // unused: must not change the Euler characteristic
  const MeshReport r = analyze_mesh(two);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.genus, 1);
  EXPECT_TRUE(r.watertight());
}

TEST(MeshReport, CountsExactlyOneCrossingPair) {
  // Two triangles, one piercing the other: one pair, found on the soup path (the mesh is open).
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, -1}, {0.5, 0.5, 1}, {1.5, 0.5, 0.5}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  const MeshReport r = analyze_mesh(m);
  EXPECT_EQ(r.self_intersecting_pairs, 1u);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.boundary_edges, 6u);
  EXPECT_EQ(r.boundary_loops, 2u);
  // Moved apart, the pair no longer crosses; touching at a shared vertex is not an intersection.
  for (std::size_t i = 3; i < 6; ++i) m.vertices[i].z() += 3.0;
  EXPECT_EQ(analyze_mesh(m).self_intersecting_pairs, 0u);
  m.triangles[1] = {0, 4, 5};
  EXPECT_EQ(analyze_mesh(m).self_intersecting_pairs, 0u);
}

TEST(MeshReport, AdjacentTrianglesOfNonManifoldMeshesAreTestedToo) {
  // A fan of three triangles on one edge (non-manifold, so the soup path) plus folds.
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}, {0.3, 0.5, 0}};
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  EXPECT_EQ(analyze_mesh(m).non_manifold_edges, 1u);
  EXPECT_EQ(analyze_mesh(m).self_intersecting_pairs, 0u);  // meeting only along the shared edge
  m.triangles.push_back({0, 5, 1});  // folded back onto triangle 0: coplanar, same side of edge 01
  EXPECT_EQ(analyze_mesh(m).self_intersecting_pairs, 1u);
  // Sharing one corner: triangle (2, a, b) whose far edge pierces triangle 2 (0 1 4).
  TriangleMesh corner;
  corner.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 0, 1}, {0.5, -0.5, 0.3}, {0.5, 0.5, 0.3}, {0.5, 0, -1}, {0.6, 0, -1.2}};
  corner.triangles = {{0, 1, 2}, {2, 3, 4}, {0, 5, 6}, {0, 6, 5}};  // the last two make an edge shared 2x
  corner.triangles.push_back({0, 5, 6});                            // ... 3x: non-manifold, soup path
  const MeshReport r = analyze_mesh(corner);
  EXPECT_GT(r.non_manifold_edges, 0u);
  EXPECT_EQ(r.self_intersecting_pairs, 1u) << format_report(r);
}

TEST(MeshReport, ClosedManifoldPredicates) {
  const MeshReport cube = analyze_mesh(make_box(Eigen::Vector3d(1, 1, 1)));
  EXPECT_TRUE(is_closed_manifold(cube));
  EXPECT_TRUE(is_watertight(cube));
  EXPECT_EQ(closed_solid_problems(cube), "");
  EXPECT_NE(format_report(cube).find("watertight            yes"), std::string::npos) << format_report(cube);
  TriangleMesh open = make_box(Eigen::Vector3d(1, 1, 1));
  open.triangles.pop_back();
  const MeshReport r = analyze_mesh(open);
  EXPECT_FALSE(is_closed_manifold(r));
  EXPECT_NE(closed_solid_problems(r).find("3 boundary edges in 1 holes"), std::string::npos) << closed_solid_problems(r);
  EXPECT_NE(format_report(r).find("<-- problem"), std::string::npos);
}

TEST(MeshReport, RealMeshesFromCgalMatchTheirKnownState) {
  const MeshReport elephant = analyze_mesh(load_mesh(test::cgal_mesh("elephant")));
  EXPECT_TRUE(elephant.watertight()) << format_report(elephant);
  EXPECT_EQ(elephant.triangles, 5558u);
  EXPECT_EQ(elephant.genus, 3);
  const MeshReport holes = analyze_mesh(load_mesh(test::cgal_mesh("elephant-with-holes")));
  EXPECT_GT(holes.boundary_loops, 0u);
  EXPECT_FALSE(holes.closed());
  const MeshReport cow = analyze_mesh(load_mesh(test::cgal_mesh("cow")));
  EXPECT_TRUE(cow.closed());
  EXPECT_GT(cow.self_intersecting_pairs, 0u);
  EXPECT_FALSE(cow.watertight());
  const MeshReport tet = analyze_mesh(load_mesh(test::cgal_mesh("tetrahedron")));
  EXPECT_TRUE(tet.closed());
  EXPECT_LT(tet.signed_volume, 0.0);
  EXPECT_EQ(analyze_mesh(load_mesh(test::cgal_mesh("knot1"))).genus, 1);
}

TEST(MeshReport, JsonCarriesTheCounts) {
  const auto json = to_json(analyze_mesh(make_box({0, 0, 0}, {1, 1, 1})));
  EXPECT_EQ(json["triangles"], 12);
  EXPECT_EQ(json["watertight"], true);
  EXPECT_EQ(json["genus"], 0);
}

// Repeated triangles cost the checks no more than linear work: the self-intersection pass tests each
// distinct triangle once. Before, a glTF instancing one cube 4000 times took 54 s (every copy's box
// against every other's: quadratic). The sweep counts the pairs tested exactly, not seconds.
TEST(MeshReport, RepeatedTrianglesAreCheckedInLinearWork) {
  const auto dir = test::temp_dir();
  std::size_t candidates_small = 0;
  for (const int copies : {250, 2000}) {
    const auto file = dir / fmt::format("cubes{}.gltf", copies);
    write_file_atomically(file, instanced_cube_gltf(copies));
    const TriangleMesh mesh = load_mesh(file);
    ASSERT_EQ(mesh.triangle_count(), 12u * copies);
    const MeshReport r = analyze_mesh(mesh);
    EXPECT_EQ(r.duplicate_triangles, 12u * (copies - 1));
    EXPECT_EQ(r.self_intersecting_pairs, 0u);
    EXPECT_GT(r.self_intersection_candidates, 0u);  // the pass ran (the copies make the cube non-manifold)
    if (copies == 250) {
      candidates_small = r.self_intersection_candidates;
    } else {
      // 8 times the triangles: linear work grows 8 times at most, quadratic 64 times; n^1.5 is 22.6.
      EXPECT_LT(static_cast<double>(r.self_intersection_candidates),
                22.6 * static_cast<double>(candidates_small))
          << candidates_small << " pairs for 250 copies";
    }
  }
}

}  // namespace
}  // namespace ts
