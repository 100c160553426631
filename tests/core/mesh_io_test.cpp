// Loading every format through assimp into one welded, flattened, double-precision mesh; bad input.
#include "core/mesh_io.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "core/mesh_report.h"
#include "tests/test_support.h"

namespace ts {
namespace {

std::string load_error(const std::filesystem::path& path) {
  try {
    load_mesh(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void write_text(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

TEST(MeshIo, ReadsEachCommonFormatAsAClosedCube) {
  for (const char* file : {"OFF/Cube.off", "PLY/cube.ply", "PLY/cube_binary.ply"}) {
    const TriangleMesh mesh = load_mesh(test::assimp_model(file));
    EXPECT_EQ(mesh.triangle_count(), 12u) << file;
    EXPECT_EQ(mesh.vertex_count(), 8u) << file;  // welded, whatever the file's per-face vertices
    EXPECT_TRUE(analyze_mesh(mesh).closed()) << file;
  }
}

TEST(MeshIo, ReadsStlObjAndGlb) {
  EXPECT_GT(load_mesh(test::assimp_model("STL/Spider_binary.stl")).triangle_count(), 100u);
  EXPECT_GT(load_mesh(test::assimp_model("OBJ/box.obj")).triangle_count(), 0u);
  EXPECT_GT(load_mesh(test::assimp_model("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb")).triangle_count(),
            1000u);
  const TriangleMesh holed = load_mesh(test::assimp_model("STL/sphereWithHole.stl"));
  EXPECT_FALSE(analyze_mesh(holed).closed());
}

TEST(MeshIo, FlattensNodeTransformsAndTriangulatesPolygons) {
  const auto dir = test::temp_dir();
  // One triangle in a buffer, instanced by two nodes: translated by (10, 0, 0), and scaled by 2.
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream(dir / "tri.bin", std::ios::binary).write(reinterpret_cast<const char*>(positions), sizeof positions);
  write_text(dir / "two.gltf", R"({
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0, "translation": [10, 0, 0]}, {"mesh": 0, "scale": [2, 2, 2]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"uri": "tri.bin", "byteLength": 36}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}]
  })");
  const TriangleMesh mesh = load_mesh(dir / "two.gltf");
  ASSERT_EQ(mesh.triangle_count(), 2u);
  const Aabb box = bounding_box(mesh);
  EXPECT_DOUBLE_EQ(box.max.x(), 11.0);
  EXPECT_DOUBLE_EQ(box.max.y(), 2.0);
  // A quad face in OBJ becomes two triangles sharing the welded vertices.
  write_text(dir / "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  const TriangleMesh quad = load_mesh(dir / "quad.obj");
  EXPECT_EQ(quad.triangle_count(), 2u);
  EXPECT_EQ(quad.vertex_count(), 4u);
}

TEST(MeshIo, MissingFileIsAClearError) {
  EXPECT_NE(load_error("/nonexistent/mesh.obj").find("mesh.obj: no such file"), std::string::npos);
}

TEST(MeshIo, DirectoryIsAClearError) {
  EXPECT_NE(load_error(test::temp_dir()).find("is a directory"), std::string::npos);
}

TEST(MeshIo, EmptyFileIsAClearError) {
  const auto dir = test::temp_dir();
  write_text(dir / "empty.obj", "");
  EXPECT_NE(load_error(dir / "empty.obj").find("is empty"), std::string::npos);
  EXPECT_FALSE(load_error(test::assimp_model("invalid/empty.off")).empty());
  EXPECT_FALSE(load_error(test::assimp_model("invalid/empty.ply")).empty());
}

TEST(MeshIo, UnknownFormatIsAClearError) {
  const auto dir = test::temp_dir();
  write_text(dir / "notes.xyz123", "this is not a mesh\n");
  EXPECT_NE(load_error(dir / "notes.xyz123").find("notes.xyz123"), std::string::npos);
  EXPECT_FALSE(load_error(dir / "notes.xyz123").empty());
}

TEST(MeshIo, MalformedFilesAreClearErrors) {
  const auto dir = test::temp_dir();
  write_text(dir / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0\n");
  write_text(dir / "bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n");
  for (const auto& file : {dir / "bad.off", dir / "bad.ply", test::assimp_model("invalid/malformed.obj")}) {
    const std::string error = load_error(file);
    EXPECT_FALSE(error.empty()) << file;
    EXPECT_NE(error.find(file.filename().string()), std::string::npos) << error;
  }
}

TEST(MeshIo, RecoverableObjDamageLoadsAndIsReported) {
  // malformed2.obj has an empty face line and a missing material: assimp recovers the other five
  // faces, and the report then shows the hole instead of the loader failing.
  const TriangleMesh mesh = load_mesh(test::assimp_model("invalid/malformed2.obj"));
  EXPECT_EQ(mesh.triangle_count(), 10u);
  EXPECT_EQ(analyze_mesh(mesh).boundary_loops, 1u);
}

TEST(MeshIo, NonFiniteCoordinatesAreRejected) {
  const auto dir = test::temp_dir();
  write_text(dir / "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string error = load_error(dir / "nan.obj");
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
}

TEST(MeshIo, PointCloudIsRejected) {
  const auto dir = test::temp_dir();
  write_text(dir / "points.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n");
  const std::string error = load_error(dir / "points.ply");
  EXPECT_NE(error.find("no triangles"), std::string::npos) << error;
}

TEST(MeshIo, ObjRoundTripKeepsFullPrecision) {
  const auto dir = test::temp_dir();
  TriangleMesh mesh;
  mesh.vertices = {{0.1, 0.2, 0.3}, {1.0 / 3.0, 0, 0}, {0, 2.0 / 3.0, 1e-7}};
  mesh.triangles = {{0, 1, 2}};
  write_obj(dir / "tri.obj", mesh);
  const TriangleMesh back = load_mesh(dir / "tri.obj");
  ASSERT_EQ(back.vertex_count(), 3u);
  // assimp keeps float positions: round trip to float precision.
  EXPECT_NEAR(back.vertices[1].x(), 1.0 / 3.0, 1e-7);
}

}  // namespace
}  // namespace ts
