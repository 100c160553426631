#include "body/particle_body.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "body/body_file.h"
#include "body/particles_ply.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/mass_properties.h"
#include "sampler/surface_points.h"
#include "tests/body/test_bodies.h"
#include "tests/input_error.h"
#include "tests/test_meshes.h"
#include "tests/test_support.h"

namespace ts::body {
namespace {

namespace fs = std::filesystem;

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

using test::input_error;

std::vector<Eigen::Vector3f> random_vectors(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  std::vector<Eigen::Vector3f> v(n);
  for (auto& p : v) p = {u(rng), u(rng), u(rng)};
  return v;
}

// A complete body: a 2 x 1 x 0.5 m box of density 1500 kg/m^3 with area-uniform surface particles.
ParticleBody box_body() {
  const TriangleMesh box = test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 1.0, 0.5));
  ParticleBody body;
  set_mass_properties(body, compute_mass_properties(box, 1500.0));
  std::mt19937_64 rng(1);
  const sampler::SurfacePoints points = sampler::sample_surface_points(box, 300, rng);
  for (std::size_t i = 0; i < points.positions.size(); ++i) {
    body.positions.push_back(points.positions[i].cast<float>());
    body.normals.push_back(points.normals[i].cast<float>());
  }
  test::set_sampling_keys(body, 0.05);
  return body;
}

TEST(ParticlesPly, BinaryRoundTripIsBitExact) {
  const fs::path file = test::temp_dir() / "p.ply";
  const auto positions = random_vectors(1000, 1);
  const auto normals = random_vectors(1000, 2);
  write_particles_ply(file, positions, normals);
  const ParticlesPly back = read_particles_ply(file);
  EXPECT_EQ(back.positions, positions);
  EXPECT_EQ(back.normals, normals);
  // 6 floats per particle after the header.
  const std::string bytes = read_file(file);
  EXPECT_EQ(bytes.size() - (bytes.find("end_header\n") + 11), 1000u * 24u);
  EXPECT_TRUE(bytes.starts_with("ply\nformat binary_little_endian 1.0\n"));

  write_particles_ply(file, positions, {});
  const ParticlesPly plain = read_particles_ply(file);
  EXPECT_EQ(plain.positions, positions);
  EXPECT_TRUE(plain.normals.empty());
}

TEST(ParticlesPly, AsciiFilesWithOtherPropertiesAndElementsAreRead) {
  const fs::path file = test::temp_dir() / "hand.ply";
  write_text(file,
             "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nelement camera 1\r\nproperty list uchar int ids\r\n"
             "element vertex 3\r\nproperty double z\r\nproperty uchar red\r\nproperty float x\r\nproperty int y\r\n"
             "element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n"
             "3 7 8 9\r\n"
             "0.5 255 1 2\r\n-1e-3 0 -4.25 7\r\n3 1 0 0\r\n"
             "3 0 1 2\r\n");
  const ParticlesPly p = read_particles_ply(file);
  ASSERT_EQ(p.positions.size(), 3u);
  EXPECT_EQ(p.positions[0], Eigen::Vector3f(1.0f, 2.0f, 0.5f));
  EXPECT_EQ(p.positions[1], Eigen::Vector3f(-4.25f, 7.0f, -1e-3f));
  EXPECT_EQ(p.positions[2], Eigen::Vector3f(0.0f, 0.0f, 3.0f));
  EXPECT_TRUE(p.normals.empty());
}

TEST(ParticlesPly, BinaryFilesWithDoublesAndAListElementFirstAreRead) {
  const fs::path file = test::temp_dir() / "mixed.ply";
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement tag 2\nproperty list uchar short values\n"
      "element vertex 2\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\n"
      "property float ny\nproperty float nz\nend_header\n";
  auto put = [&](const auto& value) { bytes.append(reinterpret_cast<const char*>(&value), sizeof value); };
  put(std::uint8_t{1});
  put(std::int16_t{-5});
  put(std::uint8_t{2});
  put(std::int16_t{3});
  put(std::int16_t{4});
  for (int i = 0; i < 2; ++i) {
    put(0.25 + i);
    put(-1.5);
    put(1e-5 * i);
    put(0.0f);
    put(0.0f);
    put(1.0f);
  }
  write_text(file, bytes);
  const ParticlesPly p = read_particles_ply(file);
  ASSERT_EQ(p.positions.size(), 2u);
  EXPECT_EQ(p.positions[1], Eigen::Vector3f(1.25f, -1.5f, 1e-5f));
  EXPECT_EQ(p.normals[1], Eigen::Vector3f(0.0f, 0.0f, 1.0f));
}

TEST(ParticlesPly, BadFilesAreInputErrorsNamingFileAndProblem) {
  const fs::path dir = test::temp_dir();
  const std::string xyz = "element vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"solid cube\nendsolid\n", "not a PLY file"},
      {"ply\nformat binary_big_endian 1.0\n" + xyz + std::string(24, '\0'), "binary_big_endian is not supported"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "no end_header"},
      {"ply\n" + xyz + "1 2 3 4 5 6\n", "no format line"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
       "no scalar property z"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "property float nx\nend_header\n1 2 3 4\n",
       "only some of nx, ny, nz"},
      {"ply\nformat binary_little_endian 1.0\n" + xyz + std::string(20, '\0'), "truncated"},
      {"ply\nformat ascii 1.0\n" + xyz + "1 2 3\n4 5\n", "truncated"},
      {"ply\nformat ascii 1.0\n" + xyz + "1 2 3\n4 five 6\n", "\"five\" in the PLY data is not a number"},
      {"ply\nformat ascii 1.0\n" + xyz + "1 2 3\n4 nan 6\n", "vertex 1: y is not a finite float"},
      {"ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
       "no vertex element"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n", "unknown type"},
      {"ply\nformat binary_little_endian 1.0\nelement vertex 99999999999\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n" + std::string(12, '\0'),
       "truncated"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path file = dir / ("bad" + std::to_string(i) + ".ply");
    write_text(file, cases[i].first);
    const std::string message = input_error([&] { read_particles_ply(file); });
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find(cases[i].second), std::string::npos) << "case " << i << ": " << message;
  }
  EXPECT_NE(input_error([&] { read_particles_ply(dir / "missing.ply"); }).find("no such file"), std::string::npos);
}

TEST(ParticleBody, JsonRoundTripKeepsEveryField) {
  const fs::path dir = test::temp_dir();
  const ParticleBody body = box_body();
  const fs::path json = write_body(dir / "out", "box", body);
  EXPECT_EQ(json, dir / "out" / "box.body.json");
  EXPECT_TRUE(fs::exists(dir / "out" / "box.particles.ply"));
  const ParticleBody back = read_body(json);
  EXPECT_EQ(back.positions, body.positions);
  EXPECT_EQ(back.normals, body.normals);
  EXPECT_EQ(back.particle_radius, body.particle_radius);
  EXPECT_EQ(back.density, body.density);
  EXPECT_EQ(back.mass, body.mass);
  EXPECT_EQ(back.volume, body.volume);
  EXPECT_EQ(back.center_of_mass, body.center_of_mass);
  EXPECT_EQ(back.inertia, body.inertia);
  EXPECT_EQ(back.principal_axes, body.principal_axes);
  EXPECT_EQ(back.principal_moments, body.principal_moments);
  EXPECT_EQ(back.sdf_voxel_size, body.sdf_voxel_size);
  EXPECT_EQ(back.source_path, body.source_path);
  EXPECT_EQ(back.source_sha256, body.source_sha256);
  EXPECT_EQ(back.quality.relative_radius, body.quality.relative_radius);
  EXPECT_EQ(back.quality.cv, body.quality.cv);
  EXPECT_EQ(back.quality.covering_radius, body.quality.covering_radius);
  EXPECT_EQ(back.quality.covering_over_r, body.quality.covering_over_r);
  EXPECT_EQ(back.quality.covering_over_r_plus_grain, body.quality.covering_over_r_plus_grain);
  EXPECT_EQ(back.quality.max_abs_phi_over_r, body.quality.max_abs_phi_over_r);
  EXPECT_EQ(back.quality.iterations, body.quality.iterations);
  EXPECT_EQ(back.quality.seconds, body.quality.seconds);
  EXPECT_EQ(back.quality.converged, body.quality.converged);
  EXPECT_EQ(back.quality.injection_rounds, body.quality.injection_rounds);
  ASSERT_TRUE(back.quality.certificate.has_value());
  EXPECT_EQ(back.quality.certificate->certified, false);
  EXPECT_EQ(back.quality.certificate->bound_over_r, 1.07);
  EXPECT_EQ(back.quality.certificate->lower_over_r, 1.02);
  EXPECT_EQ(back.quality.certificate->uncovered_subtriangles, 12u);
  EXPECT_EQ(back.quality.certificate->uncovered_area, 3e-4);
  EXPECT_EQ(back.quality.certificate->floor, 0.05 / 64.0);
  EXPECT_EQ(back.mass_method, MassMethod::ClosedMesh);
  EXPECT_TRUE(nlohmann::json::parse(read_file(json))["mass_properties_cell"].is_null());

  // Mass properties of a winding-number solid name their method and cell.
  ParticleBody open = body;
  open.mass_method = MassMethod::WindingCells;
  open.mass_cell = 0.004;
  const fs::path json3 = write_body(dir, "open", open);
  EXPECT_EQ(nlohmann::json::parse(read_file(json3))["mass_properties_method"], "winding_cells");
  EXPECT_EQ(read_body(json3).mass_method, MassMethod::WindingCells);
  EXPECT_EQ(read_body(json3).mass_cell, 0.004);

  // Interior particles (--fill): the last ones, with zero normals, counted in the JSON.
  ParticleBody filled = body;
  for (int i = 0; i < 7; ++i) {
    filled.positions.emplace_back(0.1f * static_cast<float>(i), 0.5f, 0.25f);
    filled.normals.push_back(Eigen::Vector3f::Zero());
  }
  filled.interior_count = 7;
  const fs::path json4 = write_body(dir, "filled", filled);
  EXPECT_EQ(nlohmann::json::parse(read_file(json4))["interior_particle_count"], 7);
  EXPECT_EQ(nlohmann::json::parse(read_file(json4))["particle_count"], 307);
  const ParticleBody filled_back = read_body(json4);
  EXPECT_EQ(filled_back.interior_count, 7u);
  EXPECT_EQ(filled_back.positions, filled.positions);

  // Without a grain radius the grain-relative covering ratio is null, and reads back as absent.
  ParticleBody no_grain = body;
  no_grain.quality.covering_over_r_plus_grain.reset();
  const fs::path json2 = write_body(dir, "plain", no_grain);
  EXPECT_TRUE(nlohmann::json::parse(read_file(json2))["quality"]["covering_over_r_plus_grain"].is_null());
  EXPECT_FALSE(read_body(json2).quality.covering_over_r_plus_grain.has_value());

  // A body with no certificate: not certified, its figures null, and read back as absent.
  ParticleBody uncertified = body;
  uncertified.quality.certificate.reset();
  const fs::path json5 = write_body(dir, "uncertified", uncertified);
  const auto q5 = nlohmann::json::parse(read_file(json5))["quality"];
  EXPECT_EQ(q5["coverage_certified"], false);
  EXPECT_TRUE(q5["covering_bound_over_r"].is_null());
  EXPECT_TRUE(q5["uncovered_subtriangles"].is_null());
  EXPECT_FALSE(read_body(json5).quality.certificate.has_value());
}

TEST(ParticleBody, JsonHasExactlyTheDocumentedKeys) {
  const fs::path json = write_body(test::temp_dir(), "box", box_body());
  const auto j = nlohmann::ordered_json::parse(read_file(json));
  std::vector<std::string> keys, quality_keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  for (const auto& item : j["quality"].items()) quality_keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"format_version", "units", "source", "particle_radius", "particle_count",
                                            "interior_particle_count", "particles", "density", "mass", "volume", "center_of_mass", "inertia",
                                            "principal_moments", "principal_axes", "mass_properties_method",
                                            "mass_properties_cell", "sdf_voxel_size", "quality"}));
  EXPECT_EQ(quality_keys,
            (std::vector<std::string>{"relative_radius", "cv", "covering_radius", "covering_over_r",
                                      "covering_over_r_plus_grain", "max_abs_phi_over_r", "iterations",
                                      "seconds", "converged", "injection_rounds", "coverage_certified",
                                      "covering_bound_over_r", "covering_lower_over_r",
                                      "uncovered_subtriangles", "uncovered_area", "certificate_floor"}));
  EXPECT_EQ(j["particles"], "box.particles.ply");
  EXPECT_EQ(j["particle_count"], 300);
  EXPECT_EQ(j["format_version"], kBodyFormatVersion);
  EXPECT_EQ(j["units"]["length"], "m");
  // The box's mass: 2 x 1 x 0.5 m at 1500 kg/m^3.
  EXPECT_NEAR(j["mass"].get<double>(), 1500.0, 1e-9);
}

TEST(ParticleBody, ValidationErrorsNameTheFileAndTheKey) {
  const fs::path dir = test::temp_dir();
  const fs::path json = write_body(dir, "box", box_body());
  const auto original = nlohmann::ordered_json::parse(read_file(json));
  auto error_after = [&](const std::function<void(nlohmann::ordered_json&)>& edit) {
    auto j = original;
    edit(j);
    write_text(json, j.dump(2));
    return input_error([&] { read_body(json); });
  };
  const std::string prefix = json.string() + ": ";
  EXPECT_EQ(error_after([](auto& j) { j.erase("mass"); }), prefix + "mass: missing");
  EXPECT_EQ(error_after([](auto& j) { j["quality"].erase("cv"); }), prefix + "quality.cv: missing");
  EXPECT_EQ(error_after([](auto& j) { j["source"].erase("sha256"); }), prefix + "source.sha256: missing");
  EXPECT_EQ(error_after([](auto& j) { j["particle_radius"] = -0.1; }), prefix + "particle_radius: must be > 0, not -0.1");
  EXPECT_EQ(error_after([](auto& j) { j["quality"]["converged"] = 1; }), prefix + "quality.converged: must be true or false");
  EXPECT_NE(error_after([](auto& j) { j["quality"]["colour"] = "red"; }).find(prefix + "quality.colour: unknown key"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) {
              j["format_version"] = 4;
            }).find(prefix + "format_version: 4 is not supported"),
            std::string::npos);
  // The certificate's figures must agree with each other.
  EXPECT_EQ(error_after([](auto& j) { j["quality"]["coverage_certified"] = true; }),
            prefix + "quality.coverage_certified: true with 12 uncovered sub-triangles");
  EXPECT_EQ(error_after([](auto& j) { j["quality"]["covering_lower_over_r"] = 1.5; }),
            prefix + "quality.covering_lower_over_r: 1.5 is above covering_bound_over_r 1.07");
  EXPECT_EQ(error_after([](auto& j) {
              j["quality"]["uncovered_subtriangles"] = 0;
              j["quality"]["coverage_certified"] = true;
            }),
            prefix + "quality.coverage_certified: true with covering_bound_over_r 1.07");
  EXPECT_EQ(error_after([](auto& j) { j["quality"]["covering_bound_over_r"] = nullptr; }),
            prefix + "quality.covering_lower_over_r: must be null without covering_bound_over_r");
  EXPECT_EQ(error_after([](auto& j) { j["quality"].erase("certificate_floor"); }),
            prefix + "quality.certificate_floor: missing");
  // Version 2 has no certificate keys.
  EXPECT_NE(error_after([](auto& j) {
              j["format_version"] = 2;
            }).find(prefix + "quality.coverage_certified: unknown key"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["mass_properties_method"] = "guess"; }).find(prefix + "mass_properties_method: must be"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["mass_properties_cell"] = 0.1; }).find(prefix + "mass_properties_cell: must be null"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["interior_particle_count"] = 3; }).find(prefix + "interior_particle_count: 3 interior particles, but particle 297 has a non-zero normal"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["interior_particle_count"] = 301; }).find(prefix + "interior_particle_count: 301 is more than"),
            std::string::npos);
  // Version 1 has no interior_particle_count or mass_properties_* keys.
  EXPECT_NE(error_after([](auto& j) { j["format_version"] = 1; }).find(prefix + "interior_particle_count: unknown key"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["units"]["length"] = "mm"; }).find(prefix + "units.length: must be \"m\""),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["mass"] = 1.0; }).find(prefix + "mass: 1 kg differs from density * volume"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["inertia"][0][1] = 3.0; }).find(prefix + "inertia: must be symmetric"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["principal_axes"][0] = {2.0, 0.0, 0.0}; }).find(prefix + "principal_axes:"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["center_of_mass"] = {1.0, 2.0}; }).find(prefix + "center_of_mass: must be an array"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["particle_count"] = 299; }).find(prefix + "particle_count: 299 but box.particles.ply holds 300"),
            std::string::npos);
  EXPECT_NE(error_after([](auto& j) { j["particles"] = "gone.ply"; }).find("gone.ply: no such file"), std::string::npos);
  write_text(json, "{ not json");
  EXPECT_NE(input_error([&] { read_body(json); }).find(prefix + "not valid JSON"), std::string::npos);
}

TEST(ParticleBody, VersionTwoFilesAreStillReadWithoutACertificate) {
  const fs::path dir = test::temp_dir();
  const fs::path json = write_body(dir, "box", box_body());
  auto j = nlohmann::ordered_json::parse(read_file(json));
  j["format_version"] = 2;
  for (const char* key : {"coverage_certified", "covering_bound_over_r", "covering_lower_over_r",
                          "uncovered_subtriangles", "uncovered_area", "certificate_floor"}) {
    j["quality"].erase(key);
  }
  write_text(json, j.dump(2));
  const ParticleBody back = read_body(json);
  EXPECT_FALSE(back.quality.certificate.has_value());
  EXPECT_EQ(back.quality.covering_over_r, box_body().quality.covering_over_r);
}

TEST(ParticleBody, VersionOneFilesAreStillRead) {
  const fs::path dir = test::temp_dir();
  const fs::path json = write_body(dir, "box", box_body());
  auto j = nlohmann::ordered_json::parse(read_file(json));
  j["format_version"] = 1;
  j.erase("interior_particle_count");
  j.erase("mass_properties_method");
  j.erase("mass_properties_cell");
  for (const char* key : {"coverage_certified", "covering_bound_over_r", "covering_lower_over_r",
                          "uncovered_subtriangles", "uncovered_area", "certificate_floor"}) {
    j["quality"].erase(key);
  }
  write_text(json, j.dump(2));
  const ParticleBody back = read_body(json);
  EXPECT_EQ(back.mass_method, MassMethod::ClosedMesh);
  EXPECT_EQ(back.mass, box_body().mass);
  EXPECT_NO_THROW(read_body(test::asset("bodies/cube.body.json")));  // a version 1 asset
}

TEST(ParticleBody, InvalidBodiesAreNotWritten) {
  const fs::path dir = test::temp_dir();
  ParticleBody body = box_body();
  body.mass = 0.0;
  EXPECT_NE(input_error([&] { write_body(dir, "box", body); }).find("mass: must be finite and > 0"), std::string::npos);
  body = box_body();
  body.normals.pop_back();
  EXPECT_NE(input_error([&] { write_body(dir, "box", body); }).find("299 normals for 300 particles"), std::string::npos);
  EXPECT_THROW(write_body(dir, "a/b", box_body()), InputError);
  EXPECT_TRUE(fs::is_empty(dir)) << "neither the PLY nor the JSON of a refused body is written";
}

// The grid reaches 1e9 diameters (kMaxBodyReachInDiameters): a particle beyond it from the centre
// of mass is refused by the reader (naming file, key, particle and reach) and never written; one
// just inside is read.
TEST(ParticleBody, ParticleBeyondTheGridsReachIsRefusedWhenReadAndWhenWritten) {
  const fs::path dir = test::temp_dir();
  ParticleBody body = box_body();
  const fs::path json = write_body(dir, "box", body);
  const float reach = static_cast<float>(kMaxBodyReachInDiameters * 2 * body.particle_radius);
  body.positions.at(7) = body.center_of_mass.cast<float>() + Eigen::Vector3f(0, 0.5f * reach, 0);
  write_text(dir / "box.particles.ply", particles_ply_bytes(body.positions, body.normals));
  EXPECT_NO_THROW(read_body(json));
  body.positions.at(7) = Eigen::Vector3f(0, -1e38f, 0);
  write_text(dir / "box.particles.ply", particles_ply_bytes(body.positions, body.normals));
  const std::string error = input_error([&] { read_body(json); });
  EXPECT_EQ(error.rfind(json.string() + ": particles: particle 7 lies 1e+38 m from the centre of mass", 0), 0u)
      << error;
  EXPECT_NE(error.find("reaches at most 1e+09"), std::string::npos) << error;
  EXPECT_NE(input_error([&] { write_body(dir / "other", "box", body); }).find("particle 7 lies"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "other" / "box.body.json"));
}

TEST(ParticleBody, SimulatorLoadsWhatTheSamplerWrites) {
  const ParticleBody body = box_body();
  const ParticleBody loaded = read_body(write_body(test::temp_dir(), "box", body), BodyKeys::Physical);
  ASSERT_EQ(loaded.positions.size(), body.positions.size());
  for (std::size_t i = 0; i < body.positions.size(); ++i) {
    EXPECT_EQ(loaded.positions[i].cast<double>(), body.positions[i].cast<double>());
  }
  EXPECT_EQ(loaded.particle_radius, body.particle_radius);
  EXPECT_EQ(loaded.mass, body.mass);
  EXPECT_EQ(loaded.center_of_mass, body.center_of_mass);
  EXPECT_EQ(loaded.inertia, body.inertia);
}

}  // namespace
}  // namespace ts::body

namespace ts::body {
namespace {

// A hand-written prop as the simulator's scenes use them: the physical keys only, 8 particles on the
// corners of a unit cube (normals (0, 0, 1), or none), plus `extra` keys.
fs::path write_physical_body(const fs::path& dir, const std::string& extra = "", bool normals = true) {
  std::vector<Eigen::Vector3f> corners;
  for (int i = 0; i < 8; ++i) corners.emplace_back(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1));
  write_particles_ply(dir / "cube.particles.ply", corners,
                      normals ? std::vector<Eigen::Vector3f>(8, Eigen::Vector3f::UnitZ()) : std::vector<Eigen::Vector3f>{});
  write_text(dir / "cube.body.json", R"({"particle_radius": 0.1, "particle_count": 8,
    "particles": "cube.particles.ply", "mass": 2.0, "center_of_mass": [0.5, 0.5, 0.5],
    "inertia": [[0.5, 0, 0], [0, 0.5, 0], [0, 0, 0.5]])" + extra + "}");
  return dir / "cube.body.json";
}

std::string physical_error(const std::string& extra) {
  const fs::path json = write_physical_body(test::temp_dir(), extra);
  return input_error([&] { read_body(json, BodyKeys::Physical); });
}

TEST(Body, PhysicalKeysAreEnoughForTheSimulator) {
  const fs::path json = write_physical_body(test::temp_dir());
  const ParticleBody body = read_body(json, BodyKeys::Physical);
  ASSERT_EQ(body.positions.size(), 8u);
  EXPECT_EQ(body.positions[7], Eigen::Vector3f(1, 1, 1));
  EXPECT_EQ(body.normals.size(), 8u);
  EXPECT_EQ(body.particle_radius, 0.1);
  EXPECT_EQ(body.mass, 2.0);
  EXPECT_EQ(body.center_of_mass, Eigen::Vector3d(0.5, 0.5, 0.5));
  EXPECT_EQ(body.inertia, 0.5 * Eigen::Matrix3d::Identity());
  // What the file does not give keeps the defaults.
  EXPECT_EQ(body.density, 0.0);
  EXPECT_EQ(body.interior_count, 0u);
  EXPECT_EQ(body.mass_method, MassMethod::ClosedMesh);
  EXPECT_TRUE(body.source_path.empty());
  // The sampler's bodies need every key: the first one missing is named.
  EXPECT_EQ(input_error([&] { read_body(json); }), json.string() + ": format_version: missing");
  // particle_count is optional; so are the normals.
  EXPECT_EQ(read_body(write_physical_body(test::temp_dir(), "", false), BodyKeys::Physical).normals.size(), 0u);
}

TEST(Body, PhysicalKeysMustAllBeThere) {
  for (const char* key : {"particle_radius", "mass", "center_of_mass", "inertia", "particles"}) {
    const fs::path json = write_physical_body(test::temp_dir());
    auto j = nlohmann::ordered_json::parse(read_file(json));
    j.erase(key);
    write_text(json, j.dump());
    EXPECT_EQ(input_error([&] { read_body(json, BodyKeys::Physical); }), json.string() + ": " + key + ": missing");
  }
}

TEST(Body, PhysicalKeysStillCheckEveryOtherKeyThatIsGiven) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"(, "density": -1)", "density: must be > 0, not -1"},
      {R"(, "density": 1000, "volume": 0.001)", "mass: 2 kg differs from density * volume = 1 kg"},
      {R"(, "units": {"length": "mm", "mass": "kg", "time": "s"})", "units.length: must be \"m\""},
      {R"(, "quality": {"cv": 0.1})", "quality.relative_radius: missing"},
      {R"(, "source": {"path": "cube.obj", "sha256": "abc"})",
       "source.sha256: must be 64 lowercase hex digits"},
      {R"(, "principal_axes": [[2, 0, 0], [0, 1, 0], [0, 0, 1]])",
       "principal_axes: must be three orthonormal"},
      {R"(, "principal_axes": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "principal_moments": [0.5, 0.5, 0.7])",
       "principal_axes: axis 2 is not an eigenvector"},
      {R"(, "mass_properties_cell": 0.01)", "mass_properties_cell: must be null for closed_mesh"},
      {R"(, "mass_properties_method": "winding_cells")", "mass_properties_cell: missing"},
      {R"(, "interior_particle_count": 2)",
       "interior_particle_count: 2 interior particles, but particle 6 has a non-zero normal"},
      {R"(, "format_version": 4)", "format_version: 4 is not supported"},
      {R"(, "sdf_voxel_size": "small")", "sdf_voxel_size: must be a number"},
  };
  for (const auto& [extra, expected] : cases) {
    const std::string error = physical_error(extra);
    EXPECT_NE(error.find("cube.body.json: " + expected), std::string::npos) << extra << "\n" << error;
  }
  // Given in full and consistent, they are read.
  const ParticleBody body = read_body(write_physical_body(test::temp_dir(), R"(, "density": 2000, "volume": 0.001,
      "principal_moments": [0.5, 0.5, 0.5], "principal_axes": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
      "mass_properties_method": "closed_mesh", "mass_properties_cell": null, "sdf_voxel_size": 0.05)"),
                                      BodyKeys::Physical);
  EXPECT_EQ(body.density, 2000.0);
  EXPECT_EQ(body.sdf_voxel_size, 0.05);
}

TEST(Body, UnknownKeysAreErrorsWithPhysicalKeysToo) {
  // A misspelt key never passes silently, whatever the mode.
  EXPECT_NE(physical_error(R"(, "centre_of_mass": [0, 0, 0])").find("cube.body.json: centre_of_mass: unknown key"),
            std::string::npos);
  // Version 1 has no mass_properties_method.
  EXPECT_NE(physical_error(R"(, "format_version": 1, "mass_properties_method": "closed_mesh")")
                .find("cube.body.json: mass_properties_method: unknown key"),
            std::string::npos);
}

TEST(Body, SimulatorChecksHoldWithPhysicalKeys) {
  const fs::path dir = test::temp_dir();
  const fs::path json = write_physical_body(dir);
  const auto original = nlohmann::ordered_json::parse(read_file(json));
  auto error_after = [&](const std::function<void(nlohmann::ordered_json&)>& edit) {
    auto j = original;
    edit(j);
    write_text(json, j.dump());
    return input_error([&] { read_body(json, BodyKeys::Physical); });
  };
  const std::string prefix = json.string() + ": ";
  EXPECT_EQ(error_after([](auto& j) { j["inertia"][0][1] = 0.2; }), prefix + "inertia: must be symmetric");
  EXPECT_EQ(error_after([](auto& j) { j["inertia"][2][2] = -0.5; }), prefix + "inertia: must be positive definite (kg m^2)");
  EXPECT_EQ(error_after([](auto& j) { j["particle_count"] = 9; }), prefix + "particle_count: 9 but cube.particles.ply holds 8 particles");
  EXPECT_EQ(error_after([](auto& j) { j["mass"] = 0; }), prefix + "mass: must be > 0, not 0");
  EXPECT_EQ(error_after([&](auto& j) { j["particles"] = (dir / "cube.particles.ply").string(); }),
            prefix + "particles: must be a PLY file name relative to the body file");
  write_particles_ply(dir / "empty.particles.ply", {}, {});
  EXPECT_EQ(error_after([](auto& j) {
              j["particles"] = "empty.particles.ply";
              j.erase("particle_count");
            }),
            prefix + "particles: the body has no particles");
}

TEST(Body, BundledBodiesReadAlikeWithEitherKeys) {
  for (const char* name : {"bodies/cube.body.json", "bodies/plate.body.json"}) {
    const ParticleBody all = read_body(test::asset(name));
    const ParticleBody physical = read_body(test::asset(name), BodyKeys::Physical);
    EXPECT_EQ(physical.positions, all.positions) << name;
    EXPECT_EQ(physical.normals, all.normals) << name;
    EXPECT_EQ(physical.mass, all.mass) << name;
    EXPECT_EQ(physical.inertia, all.inertia) << name;
    EXPECT_EQ(physical.principal_axes, all.principal_axes) << name;
    EXPECT_EQ(physical.quality.cv, all.quality.cv) << name;
  }
}

}  // namespace
}  // namespace ts::body
