#include "body/body_file.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <vector>

#include "body/json_fields.h"
#include "body/particles_ply.h"
#include "core/atomic_file.h"
#include "core/checked_values.h"
#include "core/error.h"
#include "core/vtk_polydata.h"

namespace ts::body {
namespace {

namespace fs = std::filesystem;
using detail::Fields;
using detail::Json;

// What the simulator needs of a body (BodyKeys::Physical).
const std::vector<std::string> kPhysicalKeys = {"particle_radius", "mass", "center_of_mass", "inertia",
                                                "particles"};

// The hidden journal of a body's replacement (write_files_atomically), beside NAME.body.json.
fs::path journal_of(const fs::path& json_path) {
  std::string name(".");  // piece by piece: GCC 12 warns falsely (-Wrestrict) on "." + std::string
  name.append(json_path.filename().string());
  name.append(".journal");
  return json_path.parent_path() / name;
}

// The files a replacement of the body `json_path` writes: the JSON and, for NAME.body.json, the
// NAME.particles.ply and NAME.particles.vtp that write_body writes beside it.
std::vector<fs::path> replaced_with(const fs::path& json_path) {
  const std::string name = json_path.filename().string();
  constexpr std::string_view kSuffix = ".body.json";
  if (!name.ends_with(kSuffix) || name.size() == kSuffix.size()) return {json_path};
  const std::string stem = name.substr(0, name.size() - kSuffix.size());
  return {json_path, json_path.parent_path() / (stem + ".particles.ply"),
          json_path.parent_path() / (stem + ".particles.vtp")};
}

// Writes `bytes` into a replacement's checked stream (core/atomic_file.h reports a failed write).
StreamWriter bytes_writer(const std::string& bytes) {
  return [&bytes](std::ostream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); };
}

// Which file a path names now (a replacement renames a new file over it): device and inode, or
// zeros when there is none.
std::pair<std::uint64_t, std::uint64_t> file_identity(const fs::path& path) {
  struct stat s {};
  if (::stat(path.c_str(), &s) != 0) return {0, 0};
  return {static_cast<std::uint64_t>(s.st_dev), static_cast<std::uint64_t>(s.st_ino)};
}

// ---------------------------------------------------------------------------------------------
// Checks shared by the writer and the reader

bool is_sha256(const std::string& s) {
  return s.size() == 64 && std::all_of(s.begin(), s.end(), [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
}

// Which of the mass-property keys beyond mass and inertia a file gave (a written body has all).
struct GivenMassKeys {
  bool density_and_volume = true;
  bool principal_axes = true;
  bool principal_moments = true;
};

// Mass properties must describe one solid: mass = density * volume, a symmetric positive definite
// inertia, and principal axes that are an orthonormal eigenbasis of it with the given moments.
void check_mass_properties(const Fields& f, const ParticleBody& b, const GivenMassKeys& given = {}) {
  if (given.density_and_volume && std::abs(b.mass - b.density * b.volume) > 1e-9 * b.mass) {
    f.fail("mass", fmt::format("{} kg differs from density * volume = {} kg", b.mass, b.density * b.volume));
  }
  const double scale = b.inertia.norm();
  if ((b.inertia - b.inertia.transpose()).norm() > 1e-9 * scale) f.fail("inertia", "must be symmetric");
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(b.inertia);
  if (!(eigen.eigenvalues().minCoeff() > 0.0)) f.fail("inertia", "must be positive definite (kg m^2)");
  // Within the mass range the simulator can invert (core/checked_values.h), as a scene's grains are.
  if (!mass_fits(b.mass)) f.fail("mass", fmt::format("{:.3g} kg is beyond 1e-100..1e+100 kg, what the simulator can invert", b.mass));
  if (!mass_fits(eigen.eigenvalues().minCoeff()) || !mass_fits(eigen.eigenvalues().maxCoeff())) {
    f.fail("inertia", fmt::format("principal moments {:.3g}..{:.3g} kg m^2 are beyond 1e-100..1e+100, what the "
                                  "simulator can invert",
                                  eigen.eigenvalues().minCoeff(), eigen.eigenvalues().maxCoeff()));
  }
  if (given.principal_axes &&
      (b.principal_axes.transpose() * b.principal_axes - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
    f.fail("principal_axes", "must be three orthonormal unit vectors");
  }
  if (!given.principal_axes || !given.principal_moments) return;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d a = b.principal_axes.col(k);
    if ((b.inertia * a - b.principal_moments[k] * a).norm() > 1e-6 * scale) {
      f.fail("principal_axes",
             fmt::format("axis {} is not an eigenvector of inertia with moment principal_moments[{}]", k, k));
    }
  }
}

// At least one particle, a normal for each or none, and (when `interior_normals`) interior
// particles exactly where the normals are zero.
// Every particle within kMaxBodyReachInDiameters particle diameters of the centre of mass: the
// simulator's grid reaches that far in cells of the largest diameter, so a body wider than that
// cannot be placed in any scene (a particle 1e38 m out was read, and refused only by a scene).
void check_particle_reach(const Fields& f, const ParticleBody& b) {
  const double reach = kMaxBodyReachInDiameters * 2 * b.particle_radius;  // m
  for (std::size_t i = 0; i < b.positions.size(); ++i) {
    const double distance = (b.positions[i].cast<double>() - b.center_of_mass).cwiseAbs().maxCoeff();
    if (distance <= reach) continue;
    f.fail("particles", fmt::format("particle {} lies {:.3g} m from the centre of mass, {:.3g} particle "
                                    "diameters; the simulator's grid reaches at most {:.0g} (within {:.3g} m)",
                                    i, distance, distance / (2 * b.particle_radius), kMaxBodyReachInDiameters,
                                    reach));
  }
}

void check_particles(const Fields& f, const ParticleBody& b, bool interior_normals = true) {
  if (b.positions.empty()) f.fail("particles", "the body has no particles");
  if (!b.normals.empty() && b.normals.size() != b.positions.size()) {
    f.fail("particles", fmt::format("{} normals for {} particles", b.normals.size(), b.positions.size()));
  }
  if (b.interior_count > b.positions.size()) {
    f.fail("interior_particle_count",
           fmt::format("{} for {} particles", b.interior_count, b.positions.size()));
  }
  check_particle_reach(f, b);
  if (!interior_normals) return;
  // Interior particles are the last ones and carry the zero normal, surface ones a non-zero one.
  for (std::size_t i = 0; i < b.normals.size(); ++i) {
    const bool interior = i >= b.positions.size() - b.interior_count;
    if (interior != (b.normals[i] == Eigen::Vector3f::Zero())) {
      f.fail("interior_particle_count", fmt::format("{} interior particles, but particle {} has {} normal",
                                                    b.interior_count, i, interior ? "a non-zero" : "a zero"));
    }
  }
}

// The certificate's figures agree with each other: the lower bound is below the upper one, and a
// body is certified exactly when no sub-triangle is left uncovered and the bound is at most r.
// `prefix`: the key path of the quality object relative to `f` ("quality." at the top level).
void check_certificate(const Fields& f, const std::string& prefix,
                       const ParticleBody::Quality::Certificate& c) {
  if (c.lower_over_r > c.bound_over_r) {
    f.fail(prefix + "covering_lower_over_r",
           fmt::format("{} is above covering_bound_over_r {}", c.lower_over_r, c.bound_over_r));
  }
  if (c.certified != (c.uncovered_subtriangles == 0)) {
    f.fail(prefix + "coverage_certified",
           fmt::format("{} with {} uncovered sub-triangles", c.certified, c.uncovered_subtriangles));
  }
  if (c.certified ? c.bound_over_r > 1.0 : c.bound_over_r < 1.0) {
    f.fail(prefix + "coverage_certified",
           fmt::format("{} with covering_bound_over_r {}", c.certified, c.bound_over_r));
  }
}

// ---------------------------------------------------------------------------------------------
// Writing

Json vector_json(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json quality_json(const ParticleBody::Quality& q) {
  Json quality;
  quality["relative_radius"] = q.relative_radius;
  quality["cv"] = q.cv;
  quality["covering_radius"] = q.covering_radius;
  quality["covering_over_r"] = q.covering_over_r;
  quality["covering_over_r_plus_grain"] =
      q.covering_over_r_plus_grain ? Json(*q.covering_over_r_plus_grain) : Json();
  quality["max_abs_phi_over_r"] = q.max_abs_phi_over_r;
  quality["iterations"] = q.iterations;
  quality["seconds"] = q.seconds;
  quality["converged"] = q.converged;
  quality["injection_rounds"] = q.injection_rounds;
  // Version 3: the certificate; null figures (and not certified) when none was computed.
  const auto& c = q.certificate;
  quality["coverage_certified"] = c && c->certified;
  quality["covering_bound_over_r"] = c ? Json(c->bound_over_r) : Json();
  quality["covering_lower_over_r"] = c ? Json(c->lower_over_r) : Json();
  quality["uncovered_subtriangles"] = c ? Json(c->uncovered_subtriangles) : Json();
  quality["uncovered_area"] = c ? Json(c->uncovered_area) : Json();
  quality["certificate_floor"] = c ? Json(c->floor) : Json();
  return quality;
}

// The keys in the order docs/body-format.md lists them.
Json body_json(const ParticleBody& body, const std::string& ply_name) {
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
  j["quality"] = quality_json(body.quality);
  return j;
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
  if (const auto& c = b.quality.certificate) {
    positive("quality.certificate_floor", c->floor);
    if (!(c->bound_over_r >= 0.0) || !std::isfinite(c->bound_over_r) || !(c->lower_over_r >= 0.0) ||
        !(c->uncovered_area >= 0.0) || !std::isfinite(c->uncovered_area)) {
      f.fail("quality.covering_bound_over_r", "certificate figures must be finite and >= 0");
    }
    check_certificate(f, "quality.", *c);
  }
  check_particles(f, b);
  check_mass_properties(f, b);
}

// ---------------------------------------------------------------------------------------------
// Reading

Json parse_json(const fs::path& json_path) {
  try {
    // body.json holds keys and a few small arrays; the particles are in the PLY beside it.
    constexpr std::uint64_t kMostJsonBytes = std::uint64_t{64} << 20;
    return Json::parse(
        read_file(json_path, kMostJsonBytes, "a body.json holds keys; the particles are in its PLY"));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(json_path, fmt::format("not valid JSON: {}", e.what()));
  }
}

// The version decides which keys belong, so it is checked first; without one (a hand-written
// physical body) the keys are those of the current version.
std::int64_t format_version(const fs::path& json_path, const Json& j) {
  const std::int64_t version =
      j.is_object() && j.contains("format_version") && j["format_version"].is_number_integer()
          ? j["format_version"].get<std::int64_t>()
          : kBodyFormatVersion;  // Fields reports what is wrong with it
  if (version < 1 || version > kBodyFormatVersion) {
    throw InputError(
        json_path, fmt::format("format_version: {} is not supported (this tetrasand reads versions 1 to {})",
                               version, kBodyFormatVersion));
  }
  return version;
}

std::vector<std::string> body_keys(std::int64_t version) {
  std::vector<std::string> keys = {"format_version", "units",          "source",  "particle_radius",
                                   "particle_count", "particles",      "density", "mass",
                                   "volume",         "center_of_mass", "inertia", "principal_moments",
                                   "principal_axes", "sdf_voxel_size", "quality"};
  if (version >= 2) {
    keys.insert(keys.begin() + 5, "interior_particle_count");
    keys.insert(keys.end() - 2, {"mass_properties_method", "mass_properties_cell"});
  }
  return keys;
}

void read_units(const fs::path& file, const Json& node) {
  const Fields f(file, node, "units.", {"length", "mass", "time"});
  const std::pair<const char*, const char*> expected[] = {{"length", "m"}, {"mass", "kg"}, {"time", "s"}};
  for (const auto& [key, unit] : expected) {
    if (f.string(key) != unit)
      f.fail(key, fmt::format("must be \"{}\" (bodies are stored in SI units)", unit));
  }
}

void read_source(const fs::path& file, const Json& node, ParticleBody& b) {
  const Fields source(file, node, "source.", {"path", "sha256"});
  b.source_path = source.string("path");
  b.source_sha256 = source.string("sha256");
  if (!is_sha256(b.source_sha256)) source.fail("sha256", "must be 64 lowercase hex digits");
}

const std::vector<std::string> kCertificateKeys = {"coverage_certified",    "covering_bound_over_r",
                                                   "covering_lower_over_r", "uncovered_subtriangles",
                                                   "uncovered_area",        "certificate_floor"};

// Version 3: the certificate's keys, all null but coverage_certified (false) when none was computed.
std::optional<ParticleBody::Quality::Certificate> read_certificate(const Fields& f) {
  const bool certified = f.boolean("coverage_certified");
  if (f.at("covering_bound_over_r").is_null()) {
    for (std::size_t k = 2; k < kCertificateKeys.size(); ++k) {
      if (!f.at(kCertificateKeys[k]).is_null())
        f.fail(kCertificateKeys[k], "must be null without covering_bound_over_r");
    }
    if (certified) f.fail("coverage_certified", "true without covering_bound_over_r");
    return std::nullopt;
  }
  ParticleBody::Quality::Certificate c;
  c.certified = certified;
  c.bound_over_r = f.non_negative("covering_bound_over_r");
  c.lower_over_r = f.non_negative("covering_lower_over_r");
  c.uncovered_subtriangles = static_cast<std::size_t>(f.count("uncovered_subtriangles"));
  c.uncovered_area = f.non_negative("uncovered_area");
  c.floor = f.positive("certificate_floor");
  return c;
}

ParticleBody::Quality read_quality(const fs::path& file, const Json& node, std::int64_t version) {
  std::vector<std::string> keys = {
      "relative_radius",    "cv",         "covering_radius", "covering_over_r", "covering_over_r_plus_grain",
      "max_abs_phi_over_r", "iterations", "seconds",         "converged",       "injection_rounds"};
  if (version >= 3) keys.insert(keys.end(), kCertificateKeys.begin(), kCertificateKeys.end());
  const Fields f(file, node, "quality.", keys);
  ParticleBody::Quality q;
  q.relative_radius = f.non_negative("relative_radius");
  q.cv = f.non_negative("cv");
  q.covering_radius = f.non_negative("covering_radius");
  q.covering_over_r = f.non_negative("covering_over_r");
  if (!f.at("covering_over_r_plus_grain").is_null()) {
    q.covering_over_r_plus_grain = f.non_negative("covering_over_r_plus_grain");
  }
  q.max_abs_phi_over_r = f.non_negative("max_abs_phi_over_r");
  q.iterations = f.small_count("iterations");
  q.seconds = f.non_negative("seconds");
  q.converged = f.boolean("converged");
  q.injection_rounds = f.small_count("injection_rounds");
  if (version >= 3) q.certificate = read_certificate(f);
  if (q.certificate) check_certificate(f, "", *q.certificate);
  return q;
}

// density to principal_axes; returns which of the keys that may be absent were given.
GivenMassKeys read_mass_properties(const Fields& f, ParticleBody& b) {
  GivenMassKeys given;
  const bool density = f.has("density");
  if (density) b.density = f.positive("density");
  b.mass = f.positive("mass");
  const bool volume = f.has("volume");
  if (volume) b.volume = f.positive("volume");
  given.density_and_volume = density && volume;
  b.center_of_mass = f.vector("center_of_mass");
  b.inertia = f.rows("inertia");
  given.principal_moments = f.has("principal_moments");
  if (given.principal_moments) b.principal_moments = f.vector("principal_moments");
  given.principal_axes = f.has("principal_axes");
  if (given.principal_axes)
    b.principal_axes = f.rows("principal_axes").transpose();  // stored one axis per array
  return given;
}

// Version 2: mass_properties_method and its cell (absent, in a physical body: closed_mesh).
void read_mass_method(const Fields& f, ParticleBody& b) {
  const std::string method = f.has("mass_properties_method") ? f.string("mass_properties_method")
                                                             : mass_method_name(MassMethod::ClosedMesh);
  if (method == mass_method_name(MassMethod::WindingCells)) {
    b.mass_method = MassMethod::WindingCells;
    b.mass_cell = f.positive("mass_properties_cell");
  } else if (method != mass_method_name(MassMethod::ClosedMesh)) {
    f.fail("mass_properties_method",
           fmt::format("must be \"closed_mesh\" or \"winding_cells\", not \"{}\"", method));
  } else if (f.has("mass_properties_cell") && !f.at("mass_properties_cell").is_null()) {
    f.fail("mass_properties_cell", "must be null for closed_mesh");
  }
}

// The PLY's name: relative to the body file, so a body folder can move.
fs::path particles_file(const Fields& f) {
  const fs::path ply = f.string("particles");
  if (ply.empty() || ply.is_absolute())
    f.fail("particles", "must be a PLY file name relative to the body file");
  return ply;
}

// particle_count and interior_particle_count as the file gives them (both >= 0), or kNotGiven.
struct Counts {
  static constexpr std::int64_t kNotGiven = -1;
  std::int64_t particles = kNotGiven;
  std::int64_t interior = kNotGiven;
};

// Reads the PLY and checks it against the counts the file gives.
void read_particles(const Fields& f, const fs::path& dir, const fs::path& ply, const Counts& counts,
                    bool interior_normals, ParticleBody& b) {
  ParticlesPly particles = read_particles_ply(dir / ply);
  b.positions = std::move(particles.positions);
  b.normals = std::move(particles.normals);
  const bool given = counts.particles != Counts::kNotGiven;
  if (given && counts.interior > counts.particles) {
    f.fail("interior_particle_count",
           fmt::format("{} is more than particle_count {}", counts.interior, counts.particles));
  }
  b.interior_count = static_cast<std::size_t>(std::max<std::int64_t>(counts.interior, 0));
  if (given && static_cast<std::uint64_t>(counts.particles) != b.positions.size()) {
    f.fail("particle_count",
           fmt::format("{} but {} holds {} particles", counts.particles, ply.string(), b.positions.size()));
  }
  check_particles(f, b, interior_normals);
}

}  // namespace

namespace {

// NAME.particles.vtp: the particles as vertex cells for ParaView and VTK (whose PLY reader gives points
// without cells, which show nothing until a Glyph filter), with radius, normal and surface (1) or
// interior (0) per particle.
std::string particles_vtp_bytes(const ParticleBody& body) {
  std::vector<double> points;
  std::vector<float> normals;
  for (const Eigen::Vector3f& p : body.positions) points.insert(points.end(), {p.x(), p.y(), p.z()});
  for (const Eigen::Vector3f& n : body.normals) normals.insert(normals.end(), {n.x(), n.y(), n.z()});
  const std::size_t n = body.positions.size();
  std::vector<std::uint8_t> surface(n, 1);
  for (std::size_t i = n - std::min(body.interior_count, n); i < n; ++i) surface[i] = 0;
  VtpPoints vtp(std::move(points));
  vtp.add("radius", 1, std::vector<double>(n, body.particle_radius));
  if (normals.size() == 3 * n) vtp.add("normal", 3, normals);
  vtp.add("surface", 1, surface);
  return vtp.bytes();
}

}  // namespace

fs::path write_body(const fs::path& dir, const std::string& name, const ParticleBody& body) {
  if (name.empty() || name.find_first_of("/\\") != std::string::npos || name == "." || name == "..") {
    throw InputError(dir / name, "a body name must be a plain file name");
  }
  const std::string ply_name = name + ".particles.ply";
  const fs::path json_path = dir / (name + ".body.json");
  validate_for_writing(json_path, body);
  // Replaced only as a whole, also when killed: both files under temporary names, then a journal
  // naming them is published, then the renames (core/atomic_file.h). A reader finds the old pair or
  // the new one.
  const std::string json_text = body_json(body, ply_name).dump(2) + "\n";
  const std::string ply_bytes = particles_ply_bytes(body.positions, body.normals);
  const std::string vtp_bytes = particles_vtp_bytes(body);
  write_files_atomically(journal_of(json_path), {{dir / ply_name, bytes_writer(ply_bytes)},
                                                 {dir / (name + ".particles.vtp"), bytes_writer(vtp_bytes)},
                                                 {json_path, bytes_writer(json_text)}});
  return json_path;
}

namespace {

ParticleBody read_body_once(const fs::path& json_path, BodyKeys keys) {
  const Json j = parse_json(json_path);
  const std::int64_t version = format_version(json_path, j);
  const std::vector<std::string> known = body_keys(version);
  const Fields f(json_path, j, "", known, keys == BodyKeys::All ? known : kPhysicalKeys);
  if (f.has("format_version")) f.count("format_version");
  if (f.has("units")) read_units(json_path, f.at("units"));
  ParticleBody b;
  if (f.has("source")) read_source(json_path, f.at("source"), b);
  b.particle_radius = f.positive("particle_radius");
  Counts counts;
  if (f.has("particle_count")) counts.particles = f.count("particle_count");
  if (version < 2) counts.interior = 0;  // version 1 bodies have no interior particles
  if (version >= 2 && f.has("interior_particle_count")) counts.interior = f.count("interior_particle_count");
  const fs::path ply = particles_file(f);
  const GivenMassKeys given = read_mass_properties(f, b);
  if (f.has("sdf_voxel_size")) b.sdf_voxel_size = f.positive("sdf_voxel_size");
  if (version >= 2) read_mass_method(f, b);
  if (f.has("quality")) b.quality = read_quality(json_path, f.at("quality"), version);
  check_mass_properties(f, b, given);
  const bool interior_normals =
      keys == BodyKeys::All || (version >= 2 && j.contains("interior_particle_count"));
  read_particles(f, json_path.parent_path(), ply, counts, interior_normals, b);
  return b;
}

}  // namespace

ParticleBody read_body(const fs::path& json_path, BodyKeys keys) {
  // A pair being replaced while it is read may be read half old, half new: read again then.
  constexpr int kAttempts = 3;
  for (int attempt = 1;; ++attempt) {
    complete_interrupted_writes(journal_of(json_path), replaced_with(json_path));
    const auto before = file_identity(json_path);
    try {
      ParticleBody body = read_body_once(json_path, keys);
      if (file_identity(json_path) == before && !fs::exists(journal_of(json_path))) return body;
    } catch (const InputError&) {
      if (file_identity(json_path) == before && !fs::exists(journal_of(json_path))) throw;
    }
    if (attempt == kAttempts) {
      throw InputError(json_path, fmt::format("was replaced while being read, {} times over", kAttempts));
    }
  }
}

}  // namespace ts::body
