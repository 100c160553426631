#include "body/particles_ply.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/ply.h"

namespace ts::body {
namespace {

namespace fs = std::filesystem;

constexpr std::array<const char*, 6> kNames = {"x", "y", "z", "nx", "ny", "nz"};

// Where x y z and nx ny nz are among the vertex element's properties.
struct VertexSlots {
  std::array<std::size_t, 6> index{};
  int count = 3;  // 6 with normals
};

VertexSlots vertex_slots(const fs::path& file, const ply::Element& vertex) {
  std::array<std::optional<std::size_t>, 6> found;
  for (std::size_t k = 0; k < kNames.size(); ++k) found[k] = vertex.scalar_property(kNames[k]);
  for (std::size_t k = 0; k < 3; ++k) {
    if (!found[k])
      throw InputError(file, fmt::format("the vertex element has no scalar property {}", kNames[k]));
  }
  const int normals = (found[3] ? 1 : 0) + (found[4] ? 1 : 0) + (found[5] ? 1 : 0);
  if (normals != 0 && normals != 3) throw InputError(file, "the vertex element has only some of nx, ny, nz");
  VertexSlots slots;
  slots.count = 3 + normals;
  for (int k = 0; k < slots.count; ++k) slots.index[k] = *found[k];
  return slots;
}

ParticlesPly read_vertices(const fs::path& file, ply::DataReader& data, const ply::Element& vertex) {
  const VertexSlots slots = vertex_slots(file, vertex);
  ParticlesPly out;
  // A lying count must not allocate more than the file could hold (every value takes a byte or more).
  const std::size_t most = data.remaining_bytes() / std::max<std::size_t>(vertex.properties.size(), 1);
  const auto reserve = static_cast<std::size_t>(std::min<std::uint64_t>(vertex.count, most));
  out.positions.reserve(reserve);
  if (slots.count == 6) out.normals.reserve(reserve);
  std::vector<double> row(vertex.properties.size());
  const auto value = [&](int k) { return row[slots.index[k]]; };
  for (std::uint64_t i = 0; i < vertex.count; ++i) {
    data.read_row(vertex, i, row);
    for (int k = 0; k < slots.count; ++k) {
      if (!std::isfinite(static_cast<float>(value(k)))) {
        throw InputError(file, fmt::format("vertex {}: {} is not a finite float", i, kNames[k]));
      }
    }
    out.positions.emplace_back(value(0), value(1), value(2));
    if (slots.count == 6) out.normals.emplace_back(value(3), value(4), value(5));
  }
  return out;
}

}  // namespace

std::string particles_ply_bytes(const std::vector<Eigen::Vector3f>& positions,
                                const std::vector<Eigen::Vector3f>& normals) {
  const bool with_normals = !normals.empty();
  if (with_normals && normals.size() != positions.size()) {
    throw Error(ExitCode::Internal, fmt::format("write_particles_ply: {} normals for {} positions",
                                                normals.size(), positions.size()));
  }
  std::string bytes = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment tetrasand particles: metres, mesh coordinates\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n{}end_header\n",
      positions.size(), with_normals ? "property float nx\nproperty float ny\nproperty float nz\n" : "");
  static_assert(std::endian::native == std::endian::little, "the floats are copied in the host's byte order");
  const std::size_t header = bytes.size();
  const std::size_t floats = with_normals ? 6 : 3;
  bytes.resize(header + positions.size() * floats * sizeof(float));
  char* out = bytes.data() + header;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    std::memcpy(out, positions[i].data(), 3 * sizeof(float));
    out += 3 * sizeof(float);
    if (with_normals) {
      std::memcpy(out, normals[i].data(), 3 * sizeof(float));
      out += 3 * sizeof(float);
    }
  }
  return bytes;
}

void write_particles_ply(const fs::path& path, const std::vector<Eigen::Vector3f>& positions,
                         const std::vector<Eigen::Vector3f>& normals) {
  write_file_atomically(path, particles_ply_bytes(positions, normals));
}

ParticlesPly read_particles_ply(const fs::path& path) {
  const std::string bytes = read_file(path);
  // A particle file is ours (little-endian by its format, docs/body-format.md) or made by hand: a
  // header keyword this reader does not know is a mistake to report, not an exporter's habit.
  const ply::HeaderRules rules{.big_endian = false, .unknown_lines = false, .lines_between_properties = true};
  const ply::Header header = ply::parse_header(path, bytes, rules);
  ply::DataReader data(path, bytes, header);
  for (const ply::Element& element : header.elements) {
    if (element.name == "vertex") return read_vertices(path, data, element);
    data.skip_element(element);
  }
  throw InputError(path, "the PLY file has no vertex element");
}

}  // namespace ts::body
