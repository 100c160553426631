#pragma once
// The mesh cases the SDF benches take on their command line: MESH@R1,R2,... where MESH is a mesh file
// or icosphere:SUBDIVISIONS (a unit-diameter sphere), shared by sdf_bench.cpp and sdf_host_build_bench.cpp.
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/mesh_io.h"
#include "core/primitives.h"

namespace ts::bench {

struct MeshCase {
  std::string mesh;
  std::vector<int> resolutions;
};

inline MeshCase parse_mesh_case(const std::string& text) {
  const auto at = text.rfind('@');
  if (at == std::string::npos)
    throw std::runtime_error("case '" + text + "' needs @resolutions, e.g. knot1.off@64,128");
  MeshCase c;
  c.mesh = text.substr(0, at);
  std::stringstream list(text.substr(at + 1));
  for (std::string item; std::getline(list, item, ',');) c.resolutions.push_back(std::stoi(item));
  return c;
}

inline TriangleMesh load_case_mesh(const std::string& name) {
  if (name.rfind("icosphere:", 0) == 0) return make_icosphere(0.5, std::stoi(name.substr(10)));
  return load_mesh(name);
}

// The case's name in tables: the file's stem, or icosphere:N as given.
inline std::string short_name(const std::string& name) {
  return name.rfind("icosphere:", 0) == 0 ? name : std::filesystem::path(name).stem().string();
}

}  // namespace ts::bench
