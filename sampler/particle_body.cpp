#include "sampler/particle_body.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string_view>

#include "core/atomic_file.h"
#include "core/error.h"

namespace ts::sampler {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;  // keeps the documented key order in written files

static_assert(std::endian::native == std::endian::little, "PLY I/O assumes a little-endian host");

// ---------------------------------------------------------------------------------------------
// PLY

struct PlyProperty {
  std::string name;
  std::string type;        // scalar type, or the item type of a list
  std::string count_type;  // non-empty for a list
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  bool ascii = false;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  // bytes
};

std::size_t ply_type_size(std::string_view type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" || type == "float32") {
    return 4;
  }
  if (type == "double" || type == "float64") return 8;
  return 0;
}

std::vector<std::string> words_of(std::string_view line) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (j > i) words.emplace_back(line.substr(i, j - i));
    i = j;
  }
  return words;
}

PlyHeader parse_ply_header(const fs::path& file, std::string_view bytes) {
  if (!bytes.starts_with("ply\n") && !bytes.starts_with("ply\r\n")) {
    throw InputError(file, "not a PLY file (it does not start with the line \"ply\")");
  }
  PlyHeader header;
  bool has_format = false;
  std::size_t pos = 0;
  for (int line_number = 1;; ++line_number) {
    const std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string_view::npos) throw InputError(file, "PLY header has no end_header line");
    std::string_view line = bytes.substr(pos, eol - pos);
    if (line.ends_with('\r')) line.remove_suffix(1);
    pos = eol + 1;
    const std::vector<std::string> w = words_of(line);
    auto fail = [&](const std::string& problem) {
      throw InputError(file, fmt::format("PLY header line {}: {}", line_number, problem));
    };
    if (line_number == 1 || w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") fail("expected \"format <ascii|binary_little_endian> 1.0\"");
      if (w[1] == "ascii") {
        header.ascii = true;
      } else if (w[1] != "binary_little_endian") {
        fail(fmt::format("format {} is not supported (use binary_little_endian or ascii)", w[1]));
      }
      has_format = true;
    } else if (w[0] == "element") {
      std::size_t count = 0;
      if (w.size() != 3 || std::from_chars(w[2].data(), w[2].data() + w[2].size(), count).ec != std::errc{}) {
        fail("expected \"element <name> <count>\"");
      }
      header.elements.push_back({w[1], count, {}});
    } else if (w[0] == "property") {
      if (header.elements.empty()) fail("property before any element");
      const bool list = w.size() == 5 && w[1] == "list";
      if (!list && w.size() != 3) fail("expected \"property <type> <name>\" or \"property list <count type> <type> <name>\"");
      PlyProperty p{list ? w[4] : w[2], list ? w[3] : w[1], list ? w[2] : ""};
      if (ply_type_size(p.type) == 0 || (list && ply_type_size(p.count_type) == 0)) {
        fail(fmt::format("unknown type in \"{}\"", line));
      }
      header.elements.back().properties.push_back(p);
    } else {
      fail(fmt::format("unknown keyword \"{}\"", w[0]));
    }
  }
  if (!has_format) throw InputError(file, "PLY header has no format line");
  header.data_offset = pos;
  return header;
}

struct TruncatedData {};

// Reads the body of a PLY one value at a time, in either encoding.
class PlyValues {
 public:
  PlyValues(const fs::path& file, std::string_view data, bool ascii) : file_(file), data_(data), ascii_(ascii) {}

  double next(const std::string& type) { return ascii_ ? next_ascii() : next_binary(type); }
  void skip_bytes(std::size_t n) {
    if (data_.size() - pos_ < n) throw TruncatedData{};
    pos_ += n;
  }
  std::size_t remaining() const { return data_.size() - pos_; }

 private:
  template <typename T>
  double load() {
    if (data_.size() - pos_ < sizeof(T)) throw TruncatedData{};
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return static_cast<double>(value);
  }
  double next_binary(const std::string& t) {
    if (t == "char" || t == "int8") return load<std::int8_t>();
    if (t == "uchar" || t == "uint8") return load<std::uint8_t>();
    if (t == "short" || t == "int16") return load<std::int16_t>();
    if (t == "ushort" || t == "uint16") return load<std::uint16_t>();
    if (t == "int" || t == "int32") return load<std::int32_t>();
    if (t == "uint" || t == "uint32") return load<std::uint32_t>();
    if (t == "float" || t == "float32") return load<float>();
    return load<double>();
  }
  double next_ascii() {
    auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (pos_ < data_.size() && space(data_[pos_])) ++pos_;
    std::size_t end = pos_;
    while (end < data_.size() && !space(data_[end])) ++end;
    if (end == pos_) throw TruncatedData{};
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(data_.data() + pos_, data_.data() + end, value);
    if (ec != std::errc{} || ptr != data_.data() + end) {
      throw InputError(file_, fmt::format("\"{}\" in the PLY data is not a number", data_.substr(pos_, end - pos_)));
    }
    pos_ = end;
    return value;
  }

  const fs::path& file_;
  std::string_view data_;
  bool ascii_;
  std::size_t pos_ = 0;
};

void skip_element(PlyValues& values, const PlyElement& element, bool ascii) {
  const bool has_list = std::any_of(element.properties.begin(), element.properties.end(),
                                    [](const PlyProperty& p) { return !p.count_type.empty(); });
  if (!ascii && !has_list) {
    std::size_t stride = 0;
    for (const auto& p : element.properties) stride += ply_type_size(p.type);
    if (stride > 0 && element.count > values.remaining() / stride) throw TruncatedData{};
    values.skip_bytes(element.count * stride);
    return;
  }
  for (std::size_t i = 0; i < element.count; ++i) {
    for (const auto& p : element.properties) {
      const double n = p.count_type.empty() ? 1.0 : values.next(p.count_type);
      for (double k = 0; k < n; ++k) values.next(p.type);
    }
  }
}

int property_index(const PlyElement& element, std::string_view name) {
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    if (element.properties[i].name == name && element.properties[i].count_type.empty()) return static_cast<int>(i);
  }
  return -1;
}

ParticlesPly read_vertices(const fs::path& file, PlyValues& values, const PlyElement& vertex) {
  std::array<int, 6> slot{};
  constexpr std::array<const char*, 6> names = {"x", "y", "z", "nx", "ny", "nz"};
  for (int k = 0; k < 6; ++k) slot[k] = property_index(vertex, names[k]);
  for (int k = 0; k < 3; ++k) {
    if (slot[k] < 0) throw InputError(file, fmt::format("the vertex element has no scalar property {}", names[k]));
  }
  const int normal_count = (slot[3] >= 0) + (slot[4] >= 0) + (slot[5] >= 0);
  if (normal_count != 0 && normal_count != 3) throw InputError(file, "the vertex element has only some of nx, ny, nz");

  ParticlesPly out;
  // A lying count must not allocate more than the file could hold (every value takes a byte or more).
  const std::size_t reserve = std::min(vertex.count, values.remaining() / std::max<std::size_t>(vertex.properties.size(), 1));
  out.positions.reserve(reserve);
  if (normal_count == 3) out.normals.reserve(reserve);
  std::vector<double> row(vertex.properties.size());
  for (std::size_t i = 0; i < vertex.count; ++i) {
    for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
      const PlyProperty& property = vertex.properties[p];
      if (property.count_type.empty()) {
        row[p] = values.next(property.type);
      } else {
        const double n = values.next(property.count_type);
        for (double k = 0; k < n; ++k) values.next(property.type);
      }
    }
    for (int k = 0; k < 3 + normal_count; ++k) {
      if (!std::isfinite(static_cast<float>(row[slot[k]]))) {
        throw InputError(file, fmt::format("vertex {}: {} is not a finite float", i, names[k]));
      }
    }
    out.positions.emplace_back(row[slot[0]], row[slot[1]], row[slot[2]]);
    if (normal_count == 3) out.normals.emplace_back(row[slot[3]], row[slot[4]], row[slot[5]]);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// body.json

Json vector_json(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json body_json(const ParticleBody& body, const std::string& ply_name) {
  const auto& q = body.quality;
  Json j;
  j["format_version"] = kBodyFormatVersion;
  j["units"] = {{"length", "m"}, {"mass", "kg"}, {"time", "s"}};
  j["source"] = {{"path", body.source_path}, {"sha256", body.source_sha256}};
  j["particle_radius"] = body.particle_radius;
  j["particle_count"] = body.positions.size();
  j["interior_particle_count"] = body.interior_count;
  j["particles"] = ply_name;
  j["density"] = body.density;
  j["mass"] = body.mass;
  j["volume"] = body.volume;
  j["center_of_mass"] = vector_json(body.center_of_mass);
  j["inertia"] = Json::array();
  for (int r = 0; r < 3; ++r) j["inertia"].push_back(vector_json(body.inertia.row(r).transpose()));
  j["principal_moments"] = vector_json(body.principal_moments);
  j["principal_axes"] = Json::array();
  for (int k = 0; k < 3; ++k) j["principal_axes"].push_back(vector_json(body.principal_axes.col(k)));
  j["mass_properties_method"] = mass_method_name(body.mass_method);
  j["mass_properties_cell"] = body.mass_method == MassMethod::WindingCells ? Json(body.mass_cell) : Json();
  j["sdf_voxel_size"] = body.sdf_voxel_size;
  Json quality;
  quality["relative_radius"] = q.relative_radius;
  quality["cv"] = q.cv;
  quality["covering_radius"] = q.covering_radius;
  quality["covering_over_r"] = q.covering_over_r;
  quality["covering_over_r_plus_grain"] = q.covering_over_r_plus_grain ? Json(*q.covering_over_r_plus_grain) : Json();
  quality["max_abs_phi_over_r"] = q.max_abs_phi_over_r;
  quality["iterations"] = q.iterations;
  quality["seconds"] = q.seconds;
  quality["converged"] = q.converged;
  quality["injection_rounds"] = q.injection_rounds;
  j["quality"] = quality;
  return j;
}

// Typed access to one JSON object of a body file; every error names the file and the key path.
class Fields {
 public:
  Fields(const fs::path& file, const Json& node, std::string prefix, std::vector<std::string> keys)
      : file_(file), node_(node), prefix_(std::move(prefix)) {
    if (!node.is_object()) fail_at(prefix_.empty() ? "(top level)" : prefix_.substr(0, prefix_.size() - 1), "must be an object");
    for (const auto& item : node.items()) {
      if (std::find(keys.begin(), keys.end(), item.key()) == keys.end()) {
        fail(item.key(), fmt::format("unknown key (format_version {} has: {})", kBodyFormatVersion, fmt::join(keys, ", ")));
      }
    }
  }

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const { fail_at(prefix_ + key, problem); }

  const Json& at(const std::string& key) const {
    if (!node_.contains(key)) fail(key, "missing");
    return node_.at(key);
  }
  double number(const std::string& key, const Json& value) const {
    if (!value.is_number()) fail(key, "must be a number");
    const double v = value.get<double>();
    if (!std::isfinite(v)) fail(key, "must be finite");
    return v;
  }
  double number(const std::string& key) const { return number(key, at(key)); }
  double positive(const std::string& key) const {
    const double v = number(key);
    if (!(v > 0.0)) fail(key, fmt::format("must be > 0, not {}", v));
    return v;
  }
  double non_negative(const std::string& key) const {
    const double v = number(key);
    if (v < 0.0) fail(key, fmt::format("must be >= 0, not {}", v));
    return v;
  }
  std::int64_t count(const std::string& key) const {
    const Json& v = at(key);
    if (!v.is_number_integer() || v.get<std::int64_t>() < 0) fail(key, "must be a non-negative integer");
    return v.get<std::int64_t>();
  }
  int small_count(const std::string& key) const {
    const std::int64_t v = count(key);
    if (v > std::numeric_limits<int>::max()) fail(key, "is too large");
    return static_cast<int>(v);
  }
  std::string string(const std::string& key) const {
    const Json& v = at(key);
    if (!v.is_string()) fail(key, "must be a string");
    return v.get<std::string>();
  }
  bool boolean(const std::string& key) const {
    const Json& v = at(key);
    if (!v.is_boolean()) fail(key, "must be true or false");
    return v.get<bool>();
  }
  Eigen::Vector3d vector(const std::string& key, const Json& value) const {
    if (!value.is_array() || value.size() != 3) fail(key, "must be an array of 3 numbers");
    return {number(key, value[0]), number(key, value[1]), number(key, value[2])};
  }
  Eigen::Vector3d vector(const std::string& key) const { return vector(key, at(key)); }
  // Three arrays of three numbers, returned as the rows of a matrix.
  Eigen::Matrix3d rows(const std::string& key) const {
    const Json& v = at(key);
    if (!v.is_array() || v.size() != 3) fail(key, "must be 3 arrays of 3 numbers");
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r) m.row(r) = vector(key, v[r]).transpose();
    return m;
  }

 private:
  [[noreturn]] void fail_at(const std::string& key_path, const std::string& problem) const {
    throw InputError(file_, fmt::format("{}: {}", key_path, problem));
  }
  const fs::path& file_;
  const Json& node_;
  std::string prefix_;
};

ParticleBody::Quality read_quality(const fs::path& file, const Json& node) {
  const Fields f(file, node, "quality.",
                 {"relative_radius", "cv", "covering_radius", "covering_over_r", "covering_over_r_plus_grain",
                  "max_abs_phi_over_r", "iterations", "seconds", "converged", "injection_rounds"});
  ParticleBody::Quality q;
  q.relative_radius = f.non_negative("relative_radius");
  q.cv = f.non_negative("cv");
  q.covering_radius = f.non_negative("covering_radius");
  q.covering_over_r = f.non_negative("covering_over_r");
  if (!f.at("covering_over_r_plus_grain").is_null()) q.covering_over_r_plus_grain = f.non_negative("covering_over_r_plus_grain");
  q.max_abs_phi_over_r = f.non_negative("max_abs_phi_over_r");
  q.iterations = f.small_count("iterations");
  q.seconds = f.non_negative("seconds");
  q.converged = f.boolean("converged");
  q.injection_rounds = f.small_count("injection_rounds");
  return q;
}

void read_units(const fs::path& file, const Json& node) {
  const Fields f(file, node, "units.", {"length", "mass", "time"});
  const std::pair<const char*, const char*> expected[] = {{"length", "m"}, {"mass", "kg"}, {"time", "s"}};
  for (const auto& [key, unit] : expected) {
    if (f.string(key) != unit) f.fail(key, fmt::format("must be \"{}\" (bodies are stored in SI units)", unit));
  }
}

bool is_sha256(const std::string& s) {
  return s.size() == 64 && std::all_of(s.begin(), s.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

// Mass properties must describe one solid: mass = density * volume, a symmetric positive definite
// inertia, and principal axes that are an orthonormal eigenbasis of it with the given moments.
void check_mass_properties(const Fields& f, const ParticleBody& b) {
  if (std::abs(b.mass - b.density * b.volume) > 1e-9 * b.mass) {
    f.fail("mass", fmt::format("{} kg differs from density * volume = {} kg", b.mass, b.density * b.volume));
  }
  const double scale = b.inertia.norm();
  if ((b.inertia - b.inertia.transpose()).norm() > 1e-9 * scale) f.fail("inertia", "must be symmetric");
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(b.inertia);
  if (!(eigen.eigenvalues().minCoeff() > 0.0)) f.fail("inertia", "must be positive definite (kg m^2)");
  if ((b.principal_axes.transpose() * b.principal_axes - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
    f.fail("principal_axes", "must be three orthonormal unit vectors");
  }
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d a = b.principal_axes.col(k);
    if ((b.inertia * a - b.principal_moments[k] * a).norm() > 1e-6 * scale) {
      f.fail("principal_axes", fmt::format("axis {} is not an eigenvector of inertia with moment principal_moments[{}]", k, k));
    }
  }
}

void check_particles(const Fields& f, const ParticleBody& b) {
  if (b.positions.empty()) f.fail("particles", "the body has no particles");
  if (!b.normals.empty() && b.normals.size() != b.positions.size()) {
    f.fail("particles", fmt::format("{} normals for {} particles", b.normals.size(), b.positions.size()));
  }
  if (b.interior_count > b.positions.size()) {
    f.fail("interior_particle_count", fmt::format("{} for {} particles", b.interior_count, b.positions.size()));
  }
  // Interior particles are the last ones and carry the zero normal, surface ones a non-zero one.
  for (std::size_t i = 0; i < b.normals.size(); ++i) {
    const bool interior = i >= b.positions.size() - b.interior_count;
    if (interior != (b.normals[i] == Eigen::Vector3f::Zero())) {
      f.fail("interior_particle_count",
             fmt::format("{} interior particles, but particle {} has {} normal", b.interior_count, i,
                         interior ? "a non-zero" : "a zero"));
    }
  }
}

void validate_for_writing(const fs::path& json_path, const ParticleBody& b) {
  const Json no_keys = Json::object();  // only Fields' error messages are needed here
  const Fields f(json_path, no_keys, "", {});
  auto positive = [&](const char* key, double v) {
    if (!(v > 0.0) || !std::isfinite(v)) f.fail(key, fmt::format("must be finite and > 0, not {}", v));
  };
  positive("particle_radius", b.particle_radius);
  positive("density", b.density);
  positive("mass", b.mass);
  positive("volume", b.volume);
  positive("sdf_voxel_size", b.sdf_voxel_size);
  if (b.mass_method == MassMethod::WindingCells) positive("mass_properties_cell", b.mass_cell);
  if (!is_sha256(b.source_sha256)) f.fail("source.sha256", "must be 64 lowercase hex digits");
  check_particles(f, b);
  check_mass_properties(f, b);
}

}  // namespace

const char* mass_method_name(MassMethod method) {
  return method == MassMethod::WindingCells ? "winding_cells" : "closed_mesh";
}

void set_mass_properties(ParticleBody& body, const MassProperties& mass) {
  body.density = mass.density;
  body.volume = mass.volume;
  body.mass = mass.mass;
  body.center_of_mass = mass.center_of_mass;
  body.inertia = mass.inertia;
  body.principal_axes = mass.principal_axes;
  body.principal_moments = mass.principal_moments;
}

void write_particles_ply(const fs::path& path, const std::vector<Eigen::Vector3f>& positions,
                         const std::vector<Eigen::Vector3f>& normals) {
  const bool with_normals = !normals.empty();
  if (with_normals && normals.size() != positions.size()) {
    throw Error(ExitCode::Internal, fmt::format("write_particles_ply: {} normals for {} positions", normals.size(), positions.size()));
  }
  std::string bytes = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment tetrasand particles: metres, mesh coordinates\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n{}end_header\n",
      positions.size(), with_normals ? "property float nx\nproperty float ny\nproperty float nz\n" : "");
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
  write_file_atomically(path, bytes);
}

ParticlesPly read_particles_ply(const fs::path& path) {
  const std::string bytes = read_file(path);
  const PlyHeader header = parse_ply_header(path, bytes);
  PlyValues values(path, std::string_view(bytes).substr(header.data_offset), header.ascii);
  for (const PlyElement& element : header.elements) {
    try {
      if (element.name == "vertex") return read_vertices(path, values, element);
      skip_element(values, element, header.ascii);
    } catch (const TruncatedData&) {
      throw InputError(path, fmt::format("truncated: the data ends inside element \"{}\" ({} announced)", element.name,
                                         element.count));
    }
  }
  throw InputError(path, "the PLY file has no vertex element");
}

fs::path write_body(const fs::path& dir, const std::string& name, const ParticleBody& body) {
  if (name.empty() || name.find_first_of("/\\") != std::string::npos || name == "." || name == "..") {
    throw InputError(dir / name, "a body name must be a plain file name");
  }
  const std::string ply_name = name + ".particles.ply";
  const fs::path json_path = dir / (name + ".body.json");
  validate_for_writing(json_path, body);
  // Replaced only as a whole: the JSON is written to its temporary file first, then the PLY is
  // written and renamed into place, then the JSON. Any failure before that last rename (disk full, a
  // directory in the way, an interrupted write) leaves the previous pair as it was and removes the
  // temporary files; and a reader that finds the new JSON finds the PLY it names.
  const std::string json_text = body_json(body, ply_name).dump(2) + "\n";
  write_atomically(json_path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(json_text.data(), static_cast<std::streamsize>(json_text.size()));
    out.close();
    if (!out) throw InputError(json_path, "cannot write file (disk full or no permission?)");
    write_particles_ply(dir / ply_name, body.positions, body.normals);
  });
  return json_path;
}

ParticleBody read_body(const fs::path& json_path) {
  Json j;
  try {
    j = Json::parse(read_file(json_path));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(json_path, fmt::format("not valid JSON: {}", e.what()));
  }
  // The version decides which keys belong, so it is checked first.
  const std::int64_t version = j.is_object() && j.contains("format_version") && j["format_version"].is_number_integer()
                                   ? j["format_version"].get<std::int64_t>()
                                   : kBodyFormatVersion;  // Fields reports what is wrong with it
  if (version < 1 || version > kBodyFormatVersion) {
    throw InputError(json_path, fmt::format("format_version: {} is not supported (this tetrasand reads versions 1 to {})",
                                            version, kBodyFormatVersion));
  }
  std::vector<std::string> keys = {"format_version", "units", "source", "particle_radius", "particle_count",
                                   "particles", "density", "mass", "volume", "center_of_mass", "inertia",
                                   "principal_moments", "principal_axes", "sdf_voxel_size", "quality"};
  if (version >= 2) {
    keys.insert(keys.begin() + 5, "interior_particle_count");
    keys.insert(keys.end() - 2, {"mass_properties_method", "mass_properties_cell"});
  }
  const Fields f(json_path, j, "", keys);
  f.count("format_version");
  read_units(json_path, f.at("units"));
  ParticleBody b;
  const Fields source(json_path, f.at("source"), "source.", {"path", "sha256"});
  b.source_path = source.string("path");
  b.source_sha256 = source.string("sha256");
  if (!is_sha256(b.source_sha256)) source.fail("sha256", "must be 64 lowercase hex digits");
  b.particle_radius = f.positive("particle_radius");
  const std::int64_t count = f.count("particle_count");
  const std::int64_t interior = version >= 2 ? f.count("interior_particle_count") : 0;
  const fs::path ply = f.string("particles");
  if (ply.empty() || ply.is_absolute()) f.fail("particles", "must be a PLY file name relative to the body file");
  b.density = f.positive("density");
  b.mass = f.positive("mass");
  b.volume = f.positive("volume");
  b.center_of_mass = f.vector("center_of_mass");
  b.inertia = f.rows("inertia");
  b.principal_moments = f.vector("principal_moments");
  b.principal_axes = f.rows("principal_axes").transpose();  // stored one axis per array
  b.sdf_voxel_size = f.positive("sdf_voxel_size");
  if (version >= 2) {
    const std::string method = f.string("mass_properties_method");
    if (method == mass_method_name(MassMethod::WindingCells)) {
      b.mass_method = MassMethod::WindingCells;
      b.mass_cell = f.positive("mass_properties_cell");
    } else if (method != mass_method_name(MassMethod::ClosedMesh)) {
      f.fail("mass_properties_method", fmt::format("must be \"closed_mesh\" or \"winding_cells\", not \"{}\"", method));
    } else if (!f.at("mass_properties_cell").is_null()) {
      f.fail("mass_properties_cell", "must be null for closed_mesh");
    }
  }
  b.quality = read_quality(json_path, f.at("quality"));
  check_mass_properties(f, b);

  ParticlesPly particles = read_particles_ply(json_path.parent_path() / ply);
  b.positions = std::move(particles.positions);
  b.normals = std::move(particles.normals);
  if (interior > count) f.fail("interior_particle_count", fmt::format("{} is more than particle_count {}", interior, count));
  b.interior_count = static_cast<std::size_t>(interior);
  if (static_cast<std::uint64_t>(count) != b.positions.size()) {
    f.fail("particle_count", fmt::format("{} but {} holds {} particles", count, ply.string(), b.positions.size()));
  }
  check_particles(f, b);
  return b;
}

}  // namespace ts::sampler
