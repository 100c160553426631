#include "core/mesh_io.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <unordered_map>
#include <unordered_set>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/mesh_file_checks.h"

namespace ts {
namespace fs = std::filesystem;

namespace {

// Only a regular file reaches assimp: a FIFO blocked it forever, a device like /dev/zero it read
// without end (core/input_file.h).
void check_readable_file(const fs::path& path) {
  if (require_regular_file(path) == 0) throw InputError(path, "is empty");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw InputError(path, "cannot be opened for reading (permission?)");
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::string lowercase_extension(const fs::path& path) { return lowercase(path.extension().string()); }

// The first bytes of a file (at most `count`), to tell its format by content.
std::string file_start(const fs::path& path, std::size_t count) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes(count, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(count));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

bool starts_as_ply(std::string_view bytes) { return bytes.starts_with("ply\n") || bytes.starts_with("ply\r\n"); }

// assimp's OFF reader claims a file by its first 3 bytes, "off" in any case.
bool starts_as_off(std::string_view bytes) { return lowercase(std::string(bytes.substr(0, 3))) == "off"; }

// OFF, PLY and glTF get a strict pass first (core/mesh_file_checks.h): assimp's readers trust declared
// counts for allocations, offsets for copies, and clamp out-of-range indices without an error. A PLY,
// an OFF and a GLB are told by their content too, whatever their name: assimp falls back to reading a
// file by its signature when the reader its extension names refuses it, so a PLY named .glb reached
// assimp's PLY reader unchecked and hung it (fuzz_mesh, 2026-12-04), and an OFF named .glb its OFF
// reader (2026-12-05: a crash, and 48 GB asked for). A file named .glb that is no binary glTF is
// refused outright: any of assimp's forty readers could claim it.
// An XML document (Collada, X3D, AMF, ...): its first character past a byte order mark and white
// space is '<'.
bool starts_as_xml(std::string_view bytes) {
  if (bytes.starts_with("\xEF\xBB\xBF")) bytes.remove_prefix(3);
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && bytes[first] == '<';
}

void check_before_assimp(const fs::path& path) {
  const std::string ext = lowercase_extension(path);
  const std::string start = file_start(path, 64);
  const bool ply_content = starts_as_ply(start);
  const bool off_content = starts_as_off(start);
  const bool glb_content = start.starts_with("glTF");  // binary glTF's magic, whatever the name
  // Collada and the other XML formats: their node trees nest as elements (check_xml_nesting).
  const bool xml_content = starts_as_xml(start) || ext == ".dae";
  if (ext != ".off" && ext != ".ply" && ext != ".gltf" && ext != ".glb" && !ply_content && !off_content &&
      !glb_content && !xml_content)
    return;
  const std::string bytes = read_file(path);
  if (glb_content) {
    detail::check_glb_file(path, bytes);
  } else if (ply_content || ext == ".ply") {
    detail::check_ply_file(path, bytes);
  } else if (off_content || ext == ".off") {
    detail::check_off_file(path, bytes);
  } else if (ext == ".gltf") {
    detail::check_gltf_json(path, bytes);
  } else if (xml_content) {
    detail::check_xml_nesting(path, bytes);
  }
  if (ext == ".glb" && !glb_content)
    throw InputError(path, "is named .glb but is not a binary glTF file (it does not start with 'glTF')");
}

struct PositionHash {
  std::size_t operator()(const Eigen::Vector3d& p) const {
    std::size_t h = 0;
    for (int a = 0; a < 3; ++a) h = h * 1000003u ^ std::hash<double>()(p[a]);
    return h;
  }
};
// Equal positions, and non-finite ones with the same bits: a NaN vertex that a file's faces share is
// one vertex (assimp's OBJ reader copies it for every corner), counted once.
struct PositionEqual {
  bool operator()(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    return a == b || std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
  }
};

std::string vertices_phrase(std::size_t count) {
  return count == 1 ? "1 vertex has" : fmt::format("{} vertices have", count);
}

// What assimp's post-processing trusts about an imported scene without checking it, checked: an
// index past a mesh's vertices is read out of bounds, a face without corners trips
// TriangulateProcess's assertion (the process aborts), and non-finite positions reach its ear
// clipping. Positions are counted once per distinct value.
void check_mesh_before_post_processing(
    const fs::path& path, const aiMesh& mesh, unsigned index,
    std::unordered_set<Eigen::Vector3d, PositionHash, PositionEqual>& non_finite) {
  const std::string which =
      fmt::format("mesh {}{}", index, mesh.mName.length ? fmt::format(" ('{}')", mesh.mName.C_Str()) : "");
  if ((mesh.mNumVertices > 0 && !mesh.mVertices) || (mesh.mNumFaces > 0 && !mesh.mFaces)) {
    throw InputError(path, which + " has no vertex or face data");
  }
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    const aiVector3D& p = mesh.mVertices[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) non_finite.emplace(p.x, p.y, p.z);
  }
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices == 0 || !face.mIndices)
      throw InputError(path, fmt::format("{}: face {} has no corners", which, f));
    for (unsigned c = 0; c < face.mNumIndices; ++c) {
      if (face.mIndices[c] >= mesh.mNumVertices) {
        throw InputError(path, fmt::format("{}: face {} refers to vertex {}, outside 0..{}", which, f,
                                           face.mIndices[c], static_cast<long long>(mesh.mNumVertices) - 1));
      }
    }
  }
}

// Nodes name meshes that exist, and the graph is a tree of bounded depth (the flattening recurses).
void check_nodes(const fs::path& path, const aiScene& scene, const aiNode& node, unsigned depth) {
  if (depth > detail::kMostNodeDepth)
    throw InputError(path,
                     fmt::format("the node hierarchy is deeper than {} levels", detail::kMostNodeDepth));
  for (unsigned k = 0; k < node.mNumMeshes; ++k) {
    if (!node.mMeshes || node.mMeshes[k] >= scene.mNumMeshes) {
      throw InputError(path,
                       fmt::format("node '{}' refers to a mesh that does not exist", node.mName.C_Str()));
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) {
    if (!node.mChildren || !node.mChildren[c])
      throw InputError(path, fmt::format("node '{}' has a missing child", node.mName.C_Str()));
    check_nodes(path, scene, *node.mChildren[c], depth + 1);
  }
}

void check_scene_before_post_processing(const fs::path& path, const aiScene& scene) {
  if (scene.mNumMeshes > 0 && !scene.mMeshes) throw InputError(path, "the file's meshes are missing");
  std::unordered_set<Eigen::Vector3d, PositionHash, PositionEqual> non_finite;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    if (!scene.mMeshes[m]) throw InputError(path, fmt::format("mesh {} is missing", m));
    check_mesh_before_post_processing(path, *scene.mMeshes[m], m, non_finite);
  }
  if (!non_finite.empty()) {
    throw InputError(
        path, fmt::format("{} non-finite coordinates (NaN or infinity)", vertices_phrase(non_finite.size())));
  }
  if (!scene.mRootNode) throw InputError(path, "the file holds no scene graph");
  check_nodes(path, scene, *scene.mRootNode, 0);
}

// The primitive types of each mesh as its faces are. Importers set or leave them; TriangulateProcess
// asserts that a mesh flagged as holding polygons has one, so they are recomputed from the faces
// (checked above: each has one corner or more).
void set_primitive_types_from_faces(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    // The scene is the importer's own, not a const object: assimp hands it out read-only only
    // because its post-processing steps are meant to be the ones to change it.
    aiMesh& mesh = *const_cast<aiMesh*>(scene.mMeshes[m]);
    unsigned types = 0;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const unsigned n = mesh.mFaces[f].mNumIndices;
      types |= n == 1   ? aiPrimitiveType_POINT
               : n == 2 ? aiPrimitiveType_LINE
               : n == 3 ? aiPrimitiveType_TRIANGLE
                        : aiPrimitiveType_POLYGON;
    }
    mesh.mPrimitiveTypes = types;
  }
}

struct Flattener {
  const aiScene* scene;
  TriangleMesh mesh;
  std::unordered_map<Eigen::Vector3d, std::uint32_t, PositionHash, PositionEqual> welded;
  std::size_t non_finite = 0, points_and_lines = 0;

  std::uint32_t vertex_index(const Eigen::Vector3d& p) {
    auto [it, inserted] = welded.try_emplace(p, static_cast<std::uint32_t>(mesh.vertices.size()));
    if (inserted) {
      mesh.vertices.push_back(p);
      if (!p.allFinite()) ++non_finite;  // a finite position beyond double's range after its transform
    }
    return it->second;
  }

  // Assimp keeps positions in float (Debian's build); transforms are composed in double here.
  void visit(const aiNode* node, const Eigen::Matrix4d& parent) {
    Eigen::Matrix4d local;
    const aiMatrix4x4& m = node->mTransformation;
    local << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
    const Eigen::Matrix4d world = parent * local;
    for (unsigned k = 0; k < node->mNumMeshes; ++k) add_mesh(*scene->mMeshes[node->mMeshes[k]], world);
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], world);
  }

  void add_mesh(const aiMesh& source, const Eigen::Matrix4d& transform) {
    std::vector<std::uint32_t> remap(source.mNumVertices);
    for (unsigned v = 0; v < source.mNumVertices; ++v) {
      const aiVector3D& p = source.mVertices[v];
      const Eigen::Vector4d x = transform * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
      remap[v] = vertex_index(x.head<3>() / x.w());
    }
    // A mirroring transform (negative determinant) flips the winding; restore outward orientation.
    const bool mirrored = transform.topLeftCorner<3, 3>().determinant() < 0.0;
    for (unsigned f = 0; f < source.mNumFaces; ++f) {
      const aiFace& face = source.mFaces[f];
      if (face.mNumIndices != 3) {
        ++points_and_lines;
        continue;
      }
      std::array<std::uint32_t, 3> t{remap[face.mIndices[0]], remap[face.mIndices[1]], remap[face.mIndices[2]]};
      if (mirrored) std::swap(t[1], t[2]);
      mesh.triangles.push_back(t);
    }
  }
};

[[noreturn]] void import_failed(const fs::path& path, const std::string& reason) {
  if (reason.find("No suitable reader") != std::string::npos) {
    throw InputError(path, "unknown or unsupported mesh format (assimp: " + reason + ")");
  }
  throw InputError(path, "cannot be read as a mesh: " + reason);
}

// The file as assimp reads it, checked, then with polygons triangulated.
const aiScene& import_scene(const fs::path& path, Assimp::Importer& importer) {
  // No post-processing while reading: the scene is checked first (check_scene_before_post_processing).
  const aiScene* scene = importer.ReadFile(path.string(), 0);
  if (!scene) import_failed(path, importer.GetErrorString());
  check_scene_before_post_processing(path, *scene);
  set_primitive_types_from_faces(*scene);
  // Triangulate polygons; keep positions as they are (no normal generation, no vertex merging that
  // depends on normals or texture coordinates: welding by position is done below). No SortByPType:
  // points and lines are skipped face by face below, and that step turns an STL solid without
  // facets into the baffling "Mesh with invalid primitive type" instead of an empty mesh.
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate);
  if (!scene) import_failed(path, importer.GetErrorString());
  return *scene;
}

}  // namespace

TriangleMesh load_mesh(const fs::path& path) {
  check_readable_file(path);
  check_before_assimp(path);
  Assimp::Importer importer;
  const aiScene& scene = import_scene(path, importer);
  Flattener flat{&scene, {}, {}, 0, 0};
  flat.visit(scene.mRootNode, Eigen::Matrix4d::Identity());
  if (flat.non_finite > 0) {
    throw InputError(
        path, fmt::format("{} non-finite coordinates after the node transforms (beyond double's range)",
                          vertices_phrase(flat.non_finite)));
  }
  if (flat.mesh.triangles.empty()) {
    throw InputError(path, flat.points_and_lines > 0 || !flat.mesh.vertices.empty()
                               ? "has no triangles (a point cloud or a set of lines?)"
                               : "holds no geometry");
  }
  // Drop vertices only points or lines used, so indices stay dense.
  std::vector<std::uint32_t> used(flat.mesh.vertices.size(), UINT32_MAX);
  TriangleMesh mesh;
  for (auto& t : flat.mesh.triangles) {
    for (auto& v : t) {
      if (used[v] == UINT32_MAX) {
        used[v] = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.push_back(flat.mesh.vertices[v]);
      }
      v = used[v];
    }
    mesh.triangles.push_back(t);
  }
  return mesh;
}

void scale_mesh(TriangleMesh& mesh, double factor) {
  if (!(factor > 0.0) || !std::isfinite(factor)) throw InputError(fmt::format("scale must be positive and finite (got {})", factor));
  for (auto& v : mesh.vertices) v *= factor;
}

void write_obj(const fs::path& path, const TriangleMesh& mesh, const std::vector<fs::path>& inputs) {
  std::string text = fmt::format("# {} vertices, {} triangles (tetrasand)\n", mesh.vertex_count(), mesh.triangle_count());
  for (const auto& v : mesh.vertices) text += fmt::format("v {:.17g} {:.17g} {:.17g}\n", v.x(), v.y(), v.z());
  for (const auto& t : mesh.triangles) text += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  write_file_atomically(path, text, inputs);
}

}  // namespace ts
