// Reading the sampler's particle rigid bodies: NAME.body.json (mass properties, particle radius,
// the PLY file name) and NAME.particles.ply (binary little-endian vertices, float x y z first).
#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <Eigen/Eigenvalues>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "sim/scene.h"

namespace ts::sim {
namespace {

namespace fs = std::filesystem;

std::size_t ply_type_size(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
      type == "float32") {
    return 4;
  }
  if (type == "double" || type == "float64") return 8;
  return 0;
}

// Vertex positions of a binary little-endian PLY whose x, y, z are floats.
std::vector<Eigen::Vector3d> read_ply_positions(const fs::path& file) {
  static_assert(std::endian::native == std::endian::little, "PLY reading assumes a little-endian host");
  const std::string bytes = read_file(file);
  const std::size_t end = bytes.find("end_header\n");
  if (bytes.rfind("ply\n", 0) != 0 || end == std::string::npos) throw InputError(file, "not a PLY file");
  std::istringstream header(bytes.substr(0, end));
  std::string line;
  std::size_t count = 0, stride = 0;
  int x = -1, y = -1, z = -1;  // byte offsets
  bool in_vertex = false, binary = false;
  while (std::getline(header, line)) {
    std::istringstream words(line);
    std::string word, type, name;
    words >> word;
    if (word == "format") {
      words >> type;
      binary = type == "binary_little_endian";
    } else if (word == "element") {
      words >> name >> count;
      in_vertex = name == "vertex";
      if (!in_vertex && x < 0) throw InputError(file, "the vertex element must come first");
    } else if (word == "property" && in_vertex) {
      words >> type >> name;
      if (type == "list") throw InputError(file, "list properties in the vertex element are not supported");
      const std::size_t size = ply_type_size(type);
      if (size == 0) throw InputError(file, fmt::format("unknown PLY type \"{}\"", type));
      const bool is_float = type == "float" || type == "float32";
      int* slot = name == "x" ? &x : name == "y" ? &y : name == "z" ? &z : nullptr;
      if (slot && !is_float) throw InputError(file, fmt::format("vertex {} must be float, not {}", name, type));
      if (slot) *slot = static_cast<int>(stride);
      stride += size;
    }
  }
  if (!binary) throw InputError(file, "only binary_little_endian PLY is supported");
  if (x < 0 || y < 0 || z < 0) throw InputError(file, "vertex element lacks float x, y, z");
  const std::size_t data = end + std::strlen("end_header\n");
  if (bytes.size() < data + count * stride) {
    throw InputError(file, fmt::format("truncated: {} vertices of {} bytes announced", count, stride));
  }
  std::vector<Eigen::Vector3d> points(count);
  for (std::size_t i = 0; i < count; ++i) {
    const char* v = bytes.data() + data + i * stride;
    float c[3];
    std::memcpy(&c[0], v + x, 4);
    std::memcpy(&c[1], v + y, 4);
    std::memcpy(&c[2], v + z, 4);
    points[i] = Eigen::Vector3d(c[0], c[1], c[2]);
  }
  return points;
}

}  // namespace

ParticleBody load_particle_body(const std::filesystem::path& body_json) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(read_file(body_json));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(body_json, fmt::format("not valid JSON: {}", e.what()));
  }
  auto number = [&](const nlohmann::json& node, const std::string& key) {
    if (!node.is_number()) throw InputError(body_json, fmt::format("{}: must be a number", key));
    return node.get<double>();
  };
  auto require = [&](const std::string& key) -> const nlohmann::json& {
    if (!j.contains(key)) throw InputError(body_json, fmt::format("{}: missing", key));
    return j.at(key);
  };
  ParticleBody body;
  body.particle_radius = number(require("particle_radius"), "particle_radius");
  body.mass = number(require("mass"), "mass");
  if (!(body.particle_radius > 0)) throw InputError(body_json, "particle_radius: must be > 0 (m)");
  if (!(body.mass > 0)) throw InputError(body_json, "mass: must be > 0 (kg)");
  const nlohmann::json& com = require("center_of_mass");
  if (!com.is_array() || com.size() != 3) throw InputError(body_json, "center_of_mass: must be [x, y, z]");
  for (int i = 0; i < 3; ++i) body.center_of_mass[i] = number(com[i], "center_of_mass");
  const nlohmann::json& inertia = require("inertia");
  if (!inertia.is_array() || inertia.size() != 3) throw InputError(body_json, "inertia: must be a 3x3 array");
  for (int r = 0; r < 3; ++r) {
    if (!inertia[r].is_array() || inertia[r].size() != 3) throw InputError(body_json, "inertia: must be a 3x3 array");
    for (int c = 0; c < 3; ++c) body.inertia(r, c) = number(inertia[r][c], "inertia");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(body.inertia);
  if ((body.inertia - body.inertia.transpose()).norm() > 1e-9 * body.inertia.norm() ||
      !(principal.eigenvalues().minCoeff() > 0)) {
    throw InputError(body_json, "inertia: must be symmetric positive definite (kg m^2)");
  }
  const nlohmann::json& particles = require("particles");
  if (!particles.is_string()) throw InputError(body_json, "particles: must be the PLY file name");
  body.particles = read_ply_positions(body_json.parent_path() / particles.get<std::string>());
  if (j.contains("particle_count") && j.at("particle_count").is_number_integer() &&
      j.at("particle_count").get<std::size_t>() != body.particles.size()) {
    throw InputError(body_json, fmt::format("particle_count: {} but the PLY holds {}",
                                            j.at("particle_count").get<std::size_t>(), body.particles.size()));
  }
  if (body.particles.empty()) throw InputError(body_json, "the body has no particles");
  return body;
}

}  // namespace ts::sim
