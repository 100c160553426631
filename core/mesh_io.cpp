#include "core/mesh_io.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <unordered_map>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/mesh_file_checks.h"

namespace ts {
namespace fs = std::filesystem;

namespace {

void check_readable_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, "no such file");
  if (fs::is_directory(path, ec)) throw InputError(path, "is a directory, not a mesh file");
  if (fs::file_size(path, ec) == 0) throw InputError(path, "is empty");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw InputError(path, "cannot be opened for reading (permission?)");
}

std::string lowercase_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// OFF and PLY get a strict pass first (core/mesh_file_checks.h): assimp's readers trust declared
// counts for allocations and clamp out-of-range indices without an error.
void check_before_assimp(const fs::path& path) {
  const std::string ext = lowercase_extension(path);
  if (ext != ".off" && ext != ".ply") return;
  const std::string bytes = read_file(path);
  if (bytes.starts_with("ply\n") || bytes.starts_with("ply\r\n") || ext == ".ply") {
    detail::check_ply_file(path, bytes);
  } else {
    detail::check_off_file(path, bytes);
  }
}

struct PositionHash {
  std::size_t operator()(const Eigen::Vector3d& p) const {
    std::size_t h = 0;
    for (int a = 0; a < 3; ++a) h = h * 1000003u ^ std::hash<double>()(p[a]);
    return h;
  }
};
struct PositionEqual {
  bool operator()(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const { return a == b; }
};

struct Flattener {
  const aiScene* scene;
  TriangleMesh mesh;
  std::unordered_map<Eigen::Vector3d, std::uint32_t, PositionHash, PositionEqual> welded;
  std::size_t non_finite = 0, points_and_lines = 0;

  std::uint32_t vertex_index(const Eigen::Vector3d& p) {
    auto [it, inserted] = welded.try_emplace(p, static_cast<std::uint32_t>(mesh.vertices.size()));
    if (inserted) mesh.vertices.push_back(p);
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
      const Eigen::Vector3d position = x.head<3>() / x.w();
      if (!position.allFinite()) ++non_finite;
      remap[v] = vertex_index(position);
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

}  // namespace

TriangleMesh load_mesh(const fs::path& path) {
  check_readable_file(path);
  check_before_assimp(path);
  Assimp::Importer importer;
  // Triangulate polygons; keep positions as they are (no normal generation, no vertex merging that
  // depends on normals or texture coordinates: welding by position is done below). No SortByPType:
  // points and lines are skipped face by face below, and that step turns an STL solid without
  // facets into the baffling "Mesh with invalid primitive type" instead of an empty mesh.
  const aiScene* scene = importer.ReadFile(path.string(), aiProcess_Triangulate);
  if (!scene) {
    const std::string reason = importer.GetErrorString();
    if (reason.find("No suitable reader") != std::string::npos) {
      throw InputError(path, "unknown or unsupported mesh format (assimp: " + reason + ")");
    }
    throw InputError(path, "cannot be read as a mesh: " + reason);
  }
  if (!scene->mRootNode) throw InputError(path, "the file holds no scene graph");
  Flattener flat{scene, {}, {}, 0, 0};
  flat.visit(scene->mRootNode, Eigen::Matrix4d::Identity());
  if (flat.non_finite > 0) {
    throw InputError(path, fmt::format("{} vertices have non-finite coordinates (NaN or infinity)", flat.non_finite));
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
