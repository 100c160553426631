#pragma once
// Helpers shared by all test executables: paths to bundled assets and to Debian's test meshes.
#include <filesystem>
#include <string>

namespace ts::test {

// <repo>/assets/<name>
std::filesystem::path asset(const std::string& name);

// A mesh from libcgal-demo's data.tar.gz (e.g. "elephant" -> data/meshes/elephant.off), unpacked on
// first use into the build tree. Fails the test (GTEST_SKIP is not used: the set-up installs it).
std::filesystem::path cgal_mesh(const std::string& name);

// A file from assimp-testmodels, e.g. "OFF/Cube.off".
std::filesystem::path assimp_model(const std::string& relative);

// A fresh, empty temporary directory unique to the running test.
std::filesystem::path temp_dir();

// Runs the tetrasand executable with `args`; returns the exit code, stdout+stderr in *output.
int run_tetrasand(const std::string& args, std::string* output = nullptr);

// `p` in single quotes, for a run_tetrasand command line (test paths hold no quote).
std::string quoted(const std::filesystem::path& p);

}  // namespace ts::test
