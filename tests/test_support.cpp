#include "tests/test_support.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <mutex>
#include <stdexcept>

namespace ts::test {

std::filesystem::path asset(const std::string& name) {
  return std::filesystem::path(TETRASAND_SOURCE_DIR) / "assets" / name;
}

std::filesystem::path cgal_mesh(const std::string& name) {
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  const std::filesystem::path root = std::filesystem::path(TETRASAND_TEST_DATA_DIR) / "cgal";
  const std::filesystem::path file = root / "data" / "meshes" / (name + ".off");
  if (!std::filesystem::exists(file)) {
    std::filesystem::create_directories(root);
    // Unpack to a private directory first so parallel ctest processes never see a half-written file.
    const std::string tmp = root.string() + "/.unpack." + std::to_string(::getpid());
    const std::string cmd = "mkdir -p '" + tmp + "' && tar -xzf '" TETRASAND_CGAL_DATA_TARBALL "' -C '" + tmp +
                            "' data/meshes/" + name + ".off && mkdir -p '" + (root / "data/meshes").string() +
                            "' && mv -f '" + tmp + "/data/meshes/" + name + ".off' '" + file.string() +
                            "'; rm -rf '" + tmp + "'";
    if (std::system(cmd.c_str()) != 0 || !std::filesystem::exists(file)) {
      throw std::runtime_error("cannot unpack " + name + ".off from " TETRASAND_CGAL_DATA_TARBALL
                               " (is libcgal-demo installed?)");
    }
  }
  return file;
}

std::filesystem::path assimp_model(const std::string& relative) {
  return std::filesystem::path(TETRASAND_ASSIMP_MODELS_DIR) / relative;
}

std::filesystem::path temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "test";
  for (char& c : name)
    if (c == '/') c = '_';
  auto dir = std::filesystem::temp_directory_path() / ("tetrasand-" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string quoted(const std::filesystem::path& p) {
  std::string out(1, '\'');  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on "'" + s + "'"
  out += p.string();
  out += '\'';
  return out;
}

namespace {

// --scan auto and --gpu-path auto calibrate once per renderer, driver and build into cache files
// (gpu/path_calibration.h): the build tree's, not the user's, shared by every test and every CLI run a
// test makes. Set before main, so in-process renderers (sim frames) read them too.
const bool kCalibrationCachesInBuildTree = [] {
  const std::filesystem::path bin = std::filesystem::path(TETRASAND_BINARY).parent_path();
  ::setenv("TETRASAND_SCAN_CACHE", (bin / "test_scan_calibration.json").c_str(), 0);
  ::setenv("TETRASAND_PREVIEW_CACHE", (bin / "test_preview_calibration.json").c_str(), 0);
  return true;
}();

}  // namespace

int run_tetrasand(const std::string& args, std::string* output) {
  (void)kCalibrationCachesInBuildTree;
  const std::string cmd = std::string("'") + TETRASAND_BINARY + "' " + args + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed");
  std::array<char, 4096> buffer{};
  std::string text;
  size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) text.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace ts::test
