#pragma once
// NAME.particles.ply, a body's particles: one vertex per particle, float x y z (m, mesh coordinates)
// and nx ny nz (unit outward normal; zero for an interior particle). Also what `tetrasand preview
// --particles` reads from any PLY of points.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace ts::body {

struct ParticlesPly {
  std::vector<Eigen::Vector3f> positions;  // m, as stored (a double in the file is rounded to float)
  std::vector<Eigen::Vector3f> normals;    // one per position, or empty when the file has no nx ny nz
};

// The bytes of a binary little-endian PLY, float x y z (and nx ny nz when `normals` is not empty;
// then it must match `positions` in size).
std::string particles_ply_bytes(const std::vector<Eigen::Vector3f>& positions,
                                const std::vector<Eigen::Vector3f>& normals);

// particles_ply_bytes written atomically to `path`.
void write_particles_ply(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& positions,
                         const std::vector<Eigen::Vector3f>& normals);

// Reads binary little-endian or ASCII PLY (hand-made files too) through core/ply.h: the vertex
// element's x y z (required) and nx ny nz (all three or none), of any numeric type; other properties
// and elements are skipped. Stricter than a mesh's PLY: unknown header keywords and big-endian data
// are errors. Throws ts::InputError naming the file: not a PLY, unsupported format, missing
// properties, truncated data, values that are not finite floats.
ParticlesPly read_particles_ply(const std::filesystem::path& path);

}  // namespace ts::body
