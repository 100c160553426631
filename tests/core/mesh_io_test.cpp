// Loading every format through assimp into one welded, flattened, double-precision mesh; bad input.
#include "core/mesh_io.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <utility>

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
  // The spider in three encodings: the OBJ's 19 meshes share positions that are welded across meshes.
  for (const char* file : {"STL/Spider_ascii.stl", "STL/Spider_binary.stl", "OBJ/spider.obj"}) {
    const TriangleMesh spider = load_mesh(test::assimp_model(file));
    EXPECT_EQ(spider.triangle_count(), 1368u) << file;
    EXPECT_EQ(spider.vertex_count(), 722u) << file;
  }
  const TriangleMesh box = load_mesh(test::assimp_model("OBJ/box.obj"));
  EXPECT_EQ(box.triangle_count(), 12u);
  EXPECT_TRUE(analyze_mesh(box).watertight());
  EXPECT_GT(load_mesh(test::assimp_model("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb")).triangle_count(),
            1000u);
  const MeshReport holed = analyze_mesh(load_mesh(test::assimp_model("STL/sphereWithHole.stl")));
  EXPECT_FALSE(holed.closed());
  EXPECT_EQ(holed.boundary_edges, 9u);
  EXPECT_EQ(holed.boundary_loops, 1u);
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

TEST(MeshIo, MirroringNodeTransformKeepsTrianglesOutward) {
  const auto dir = test::temp_dir();
  // A closed, outward tetrahedron instanced by a node that mirrors x: the winding must be restored.
  const float positions[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::uint16_t indices[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  {
    std::ofstream bin(dir / "tet.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(positions), sizeof positions);
    bin.write(reinterpret_cast<const char*>(indices), sizeof indices);
  }
  write_text(dir / "mirrored.gltf", R"({
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0, "scale": [-1, 1, 1], "translation": [5, 0, 0]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"uri": "tet.bin", "byteLength": 72}],
    "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 1]},
                  {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}]
  })");
  const TriangleMesh mesh = load_mesh(dir / "mirrored.gltf");
  ASSERT_EQ(mesh.triangle_count(), 4u);
  const MeshReport report = analyze_mesh(mesh);
  EXPECT_TRUE(report.watertight()) << format_report(report);
  EXPECT_NEAR(report.signed_volume, 1.0 / 6.0, 1e-12);
  EXPECT_DOUBLE_EQ(bounding_box(mesh).min.x(), 4.0);
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

TEST(MeshIo, HugeDeclaredCountsFailFastWithoutAllocating) {
  // assimp's own regression file: an OFF header declaring 3.5e11 vertices. Assimp would reserve memory
  // for all of them; the strict pre-check streams and stops where the data ends.
  const std::string off = load_error(test::assimp_model("invalid/OutOfMemory.off"));
  EXPECT_NE(off.find("declares 353535235358 vertices but the file ends after 14"), std::string::npos) << off;
  const auto dir = test::temp_dir();
  write_text(dir / "huge.ply",
             "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
             "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n");
  const std::string ply = load_error(dir / "huge.ply");
  EXPECT_NE(ply.find("declares 4000000000 'vertex' elements but the file ends in number 0"), std::string::npos) << ply;
}

TEST(MeshIo, OutOfRangeFaceIndicesAreErrorsNotClamped) {
  // Assimp's OFF and PLY readers clamp or replace such indices and load a wrong mesh without an error.
  const auto dir = test::temp_dir();
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n";
  write_text(dir / "index.off", "OFF\n3 1 0\n" + vertices + "3 0 1 7\n");
  write_text(dir / "negative.off", "OFF\n# a comment line\n3 1 0\n" + vertices + "3 0 -2 1\n");
  write_text(dir / "short.off", "OFF\n3 1 0\n" + vertices + "3 0 1\n");
  write_text(dir / "truncated.off", "OFF\n3 2 0\n" + vertices + "3 0 1 2\n");
  write_text(dir / "index.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n" + vertices + "3 0 1 9\n");
  const std::pair<const char*, const char*> cases[] = {
      {"index.off", "line 6: face 0 refers to vertex '7', outside 0..2"},
      {"negative.off", "line 7: face 0 refers to vertex '-2', outside 0..2"},
      {"short.off", "line 6: face 0 declares 3 corners but lists 2"},
      {"truncated.off", "the header declares 2 faces but the file ends after 1"},
      {"index.ply", "line 13: face 0 refers to vertex 9, outside 0..2"},
  };
  for (const auto& [file, expected] : cases) {
    const std::string error = load_error(dir / file);
    EXPECT_NE(error.find(std::string(file) + ": " + expected), std::string::npos) << error;
  }
}

TEST(MeshIo, BinaryPlyWithOutOfRangeIndexIsAnError) {
  const auto dir = test::temp_dir();
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  bytes += std::string(36, '\0');                  // three vertices at the origin (zero is zero in either order)
  bytes += std::string("\x03\0\0\0\0\0\0\0\x01\0\0\x01\0", 13);  // 3 corners: 0, 1, 256 (big-endian)
  write_text(dir / "big.ply", bytes);
  const std::string error = load_error(dir / "big.ply");
  EXPECT_NE(error.find("face 0 refers to vertex 256, outside 0..2"), std::string::npos) << error;
}

TEST(MeshIo, NonFiniteCoordinatesAreRejected) {
  const auto dir = test::temp_dir();
  write_text(dir / "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string error = load_error(dir / "nan.obj");
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
  // The box's 24 vertices (4 a face) stand at its 8 corners, all infinite: 8 positions, counted once.
  const std::string glb = load_error(test::assimp_model("glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb"));
  EXPECT_NE(glb.find("8 vertices have non-finite coordinates"), std::string::npos) << glb;
}

TEST(MeshIo, ANonFiniteVertexIsCountedOnceHoweverManyFacesShareIt) {
  // Assimp's OBJ reader copies a vertex for every corner that uses it: 3 copies of the NaN one here.
  const auto dir = test::temp_dir();
  write_text(dir / "nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  EXPECT_NE(load_error(dir / "nan.obj").find("nan.obj: 1 vertex has non-finite coordinates"),
            std::string::npos)
      << load_error(dir / "nan.obj");
  write_text(dir / "two.obj", "v nan 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n");
  EXPECT_NE(load_error(dir / "two.obj").find("2 vertices have non-finite"), std::string::npos)
      << load_error(dir / "two.obj");
}

// Files that crashed the loader (assimp assertions, segfaults) or that assimp misread without an
// error, kept in tests/core/bad_meshes/ (README.md there says what each did): each is now an
// InputError naming the file and the problem.
TEST(MeshIo, InputsThatCrashedOrWereMisreadAreClearErrors) {
  const std::pair<const char*, const char*> cases[] = {
      {"ply-face-without-corners-ascii.ply", "line 16: face 2 has 0 corners; a face needs at least 3"},
      {"ply-face-without-corners-binary.ply", "face 2 has 0 corners; a face needs at least 3"},
      {"ply-junk-line-between-properties-binary.ply",
       "line 6: 'property float y' follows line 5 ('junk line here') inside element 'vertex'"},
      {"ply-comment-between-properties-ascii.ply",
       "line 6: 'property float y' follows line 5 ('comment a wrapped comment') inside element 'vertex'"},
      {"ply-content-named-glb-hangs-assimp.glb", "the PLY header has no end_header line"},
      {"glb-chunk-longer-than-the-file.glb", "the GLB header says the file is 1900 bytes long; it is 267"},
      {"off-content-named-glb-huge-count.glb",
       "line 2: vertex and face counts must be non-negative integers (got '3999"},
      {"off-content-named-glb-crashes-assimp.glb",
       "line 11: face 0 must start with its number of corners, at least 3 (got '0.500000')"},
      {"glb-accessor-past-its-buffer-view.glb",
       "glTF: accessor 2 reads 24 elements of 12 bytes, 12 apart, from byte 5 of bufferView 2: up to byte 293, "
       "past its 288 bytes"},
      {"ply-data-on-the-end-header-line-binary.ply",
       "line 5: the end_header line holds more than 'end_header' (the data must start on the next line)"},
      {"glb-line-loop-without-positions.glb",
       "glTF: mesh 0 primitive 0 has no POSITION attribute: its faces would have no vertices"},
  };
  const std::filesystem::path dir = std::filesystem::path(TETRASAND_SOURCE_DIR) / "tests/core/bad_meshes";
  std::size_t checked = 0;
  for (const auto& [file, expected] : cases) {
    const std::string error = load_error(dir / file);
    EXPECT_NE(error.find(std::string(file) + ": " + expected), std::string::npos) << error;
    ++checked;
  }
  // Every file of the folder (fuzz findings included) is refused with its name, never a crash.
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".md") continue;
    ++files;
    const std::string error = load_error(entry.path());
    EXPECT_NE(error.find(entry.path().filename().string() + ": "), std::string::npos)
        << entry.path() << ": " << error;
  }
  EXPECT_GE(files, checked);
}

// assimp's glTF 2 reader copies `count` elements from the offsets a file declares without comparing
// them with the buffer (an accessor 5 bytes past its view read past the GLB's BIN block: fuzz_mesh).
TEST(MeshIo, GltfOffsetsAndLengthsMustLieInsideTheirBuffers) {
  const auto dir = test::temp_dir();
  // One triangle's 36 bytes of float positions, base64: the same bytes as tri.bin below.
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream(dir / "tri.bin", std::ios::binary).write(reinterpret_cast<const char*>(positions), sizeof positions);
  const std::string base64 = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";
  const auto gltf = [](const std::string& buffer, const std::string& view, const std::string& accessor,
                       const std::string& primitive = R"({"attributes": {"POSITION": 0}})") {
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
      "meshes": [{"primitives": [)" + primitive + R"(]}], "buffers": [)" + buffer + R"(], "bufferViews": [)" + view +
           R"(], "accessors": [)" + accessor + "]}";
  };
  const std::string data_buffer = R"({"uri": "data:application/octet-stream;base64,)" + base64 + R"(", "byteLength": 36})";
  const std::string good_view = R"({"buffer": 0, "byteLength": 36})";
  const std::string good_accessor = R"({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                                        "min": [0, 0, 0], "max": [1, 1, 0]})";
  write_text(dir / "good.gltf", gltf(data_buffer, good_view, good_accessor));
  EXPECT_EQ(load_mesh(dir / "good.gltf").triangle_count(), 1u);
  write_text(dir / "good_file.gltf", gltf(R"({"uri": "tri.bin", "byteLength": 36})", good_view, good_accessor));
  EXPECT_EQ(load_mesh(dir / "good_file.gltf").triangle_count(), 1u);

  const std::pair<std::string, std::string> cases[] = {
      {gltf(R"({"uri": "data:application/octet-stream;base64,)" + base64 + R"(", "byteLength": 48})", good_view,
            good_accessor),
       "glTF: buffer 0 declares 48 bytes; its data has 36"},
      {gltf(R"({"uri": "tri.bin", "byteLength": 40})", good_view, good_accessor),
       "glTF: buffer 0 declares 40 bytes; its data has 36"},
      {gltf(data_buffer, R"({"buffer": 0, "byteOffset": 4, "byteLength": 36})", good_accessor),
       "glTF: bufferView 0 spans bytes 4 to 40 of buffer 0, which has 36"},
      {gltf(data_buffer, R"({"buffer": 1, "byteLength": 36})", good_accessor),
       "glTF: bufferView 0 refers to buffers[1]; there are 1"},
      {gltf(data_buffer, good_view, R"({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"})"),
       "glTF: accessor 0 reads 4 elements of 12 bytes, 12 apart, from byte 0 of bufferView 0: up to byte 48, past "
       "its 36 bytes"},
      {gltf(data_buffer, R"({"buffer": 0, "byteLength": 36, "byteStride": 16})",
            R"({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"})"),
       "glTF: accessor 0 reads 3 elements of 12 bytes, 16 apart, from byte 0 of bufferView 0: up to byte 44"},
      {gltf(data_buffer, R"({"buffer": 0, "byteLength": 36, "byteStride": 0})",
            R"({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"})"),
       "glTF: accessor 0 reads 4 elements of 12 bytes, 12 apart, from byte 0 of bufferView 0: up to byte 48"},
      {gltf(data_buffer, good_view,
            R"({"bufferView": 0, "byteOffset": -4, "componentType": 5126, "count": 3, "type": "VEC3"})"),
       "glTF: accessor 0: 'byteOffset' is -4, not a whole number from 0 to 2^53"},
      {gltf(data_buffer, good_view, R"({"bufferView": 0, "componentType": 5127, "count": 3, "type": "VEC3"})"),
       "glTF: accessor 0 has componentType 5127, which glTF 2.0 does not define"},
      {gltf(data_buffer, good_view, good_accessor, R"({"attributes": {"POSITION": 0}, "indices": 5})"),
       "glTF: mesh 0 primitive 0 refers to accessors[5]; there are 1"},
      {gltf(data_buffer, good_view, good_accessor, R"({"attributes": {"POSITION": 2}})"),
       "glTF: mesh 0 primitive 0 attribute POSITION refers to accessors[2]; there are 1"},
      {"{\"asset\": ", "glTF: its JSON does not parse"},
      {gltf(data_buffer, good_view, good_accessor, R"({"attributes": {"NORMAL": 0}, "mode": 2})"),
       "glTF: mesh 0 primitive 0 has no POSITION attribute"},
  };
  int n = 0;
  for (const auto& [text, expected] : cases) {
    const std::string name = "bad" + std::to_string(n++) + ".gltf";
    write_text(dir / name, text);
    const std::string error = load_error(dir / name);
    EXPECT_NE(error.find(name + ": " + expected), std::string::npos) << "case " << n - 1 << ": " << error;
  }
}

TEST(MeshIo, PlyFacesNeedThreeCornersAndAsciiRowsALineEach) {
  const auto dir = test::temp_dir();
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  write_text(dir / "line.ply", header + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n");
  write_text(dir / "two_rows.ply", header + "0 0 0 1 0 0\n0 1 0\n3 0 1 2\n");
  write_text(dir / "split_row.ply", header + "0 0\n0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write_text(dir / "float_index.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n");
  const std::pair<const char*, const char*> cases[] = {
      {"line.ply", "line 13: face 0 has 2 corners; a face needs at least 3"},
      {"two_rows.ply", "line 10: 'vertex' 1 does not stand on a line of its own"},
      {"split_row.ply", "line 10: 'vertex' 0 does not stand on a line of its own"},
      {"float_index.ply", "line 13: face 0 refers to vertex 1.5, outside 0..2"},
  };
  for (const auto& [file, expected] : cases) {
    const std::string error = load_error(dir / file);
    EXPECT_NE(error.find(std::string(file) + ": " + expected), std::string::npos) << error;
  }
}

TEST(MeshIo, PlyWithoutAVertexElementIsAnError) {
  const auto dir = test::temp_dir();
  write_text(dir / "no_vertex.ply", "ply\nformat binary_little_endian 1.0\ncomment nothing else\nend_header\n");
  EXPECT_NE(load_error(dir / "no_vertex.ply")
                .find("no_vertex.ply: the PLY header declares no vertex element (a mesh needs one, with x, y and z)"),
            std::string::npos)
      << load_error(dir / "no_vertex.ply");
}

TEST(MeshIo, PlyWithoutACoordinateIsAnErrorNotZero) {
  // Assimp reads a missing y as 0 and loads a flattened mesh without a word.
  const auto dir = test::temp_dir();
  write_text(dir / "no_y.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float z\nelement face 1\n"
             "property list uchar int vertex_indices\nend_header\n0 0\n1 0\n0 1\n3 0 1 2\n");
  EXPECT_NE(load_error(dir / "no_y.ply").find("no_y.ply: the vertex element has no scalar property y"),
            std::string::npos)
      << load_error(dir / "no_y.ply");
  write_text(dir / "no_faces.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty uchar flags\nend_header\n0 0 0\n1 0 0\n0 1 0\n1\n");
  EXPECT_NE(load_error(dir / "no_faces.ply").find("element 'face' has no list property vertex_indices"),
            std::string::npos)
      << load_error(dir / "no_faces.ply");
}

TEST(MeshIo, WrappedCommentsOutsideElementsStillLoad) {
  // Exporters wrap long comments onto lines of their own (Blender's Wuson.ply): outside an element's
  // properties assimp skips them as this reader does.
  EXPECT_GT(load_mesh(test::assimp_model("PLY/Wuson.ply")).triangle_count(), 1000u);
  const auto dir = test::temp_dir();
  write_text(
      dir / "between.ply",
      "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nwrapped comment text\nelement face 4\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const MeshReport report = analyze_mesh(load_mesh(dir / "between.ply"));
  EXPECT_TRUE(report.watertight()) << format_report(report);
}

TEST(MeshIo, PointCloudIsRejected) {
  const auto dir = test::temp_dir();
  write_text(dir / "points.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n");
  const std::string error = load_error(dir / "points.ply");
  EXPECT_NE(error.find("no triangles"), std::string::npos) << error;
  write_text(dir / "no_facets.stl", "solid nothing\nendsolid nothing\n");
  EXPECT_NE(load_error(dir / "no_facets.stl").find("no_facets.stl: holds no geometry"), std::string::npos)
      << load_error(dir / "no_facets.stl");
  for (const char* file : {"OBJ/point_cloud.obj", "OBJ/testpoints.obj", "OBJ/testline.obj"}) {
    EXPECT_NE(load_error(test::assimp_model(file)).find("has no triangles"), std::string::npos) << file;
  }
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
