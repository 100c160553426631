#pragma once
// Reading meshes: every format assimp knows (OBJ, PLY, STL, OFF, glTF/GLB, FBX, ...) into the one
// indexed triangle mesh (core/mesh.h): polygons triangulated, every mesh of the node graph flattened
// with its accumulated node transform, vertices welded by exact position, coordinates in double.
// Problems throw ts::InputError naming the file and the problem.
#include <filesystem>
#include <vector>

#include "core/mesh.h"

namespace ts {

TriangleMesh load_mesh(const std::filesystem::path& path);

// Uniform scaling, e.g. --scale 1000 for a mesh in metres used in millimetres.
void scale_mesh(TriangleMesh& mesh, double factor);

// Wavefront OBJ, written atomically; refuses to overwrite any of `inputs`.
void write_obj(const std::filesystem::path& path, const TriangleMesh& mesh,
               const std::vector<std::filesystem::path>& inputs = {});

}  // namespace ts
