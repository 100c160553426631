#include "scene/vtk_files.h"

#include <gtest/gtest.h>

#include <cstring>
#include <regex>
#include <string>

#include "core/atomic_file.h"
#include "sim/grain.h"
#include "tests/test_support.h"

namespace ts::scene {
namespace {

// The values of the appended array `name` of a .vtp written by write_particles_vtp.
template <typename T>
std::vector<T> appended_array(const std::string& vtp, const std::string& name) {
  const std::regex element("<DataArray type=\"[A-Za-z0-9]+\" Name=\"" + name + "\"[^>]*offset=\"([0-9]+)\"/>");
  std::smatch m;
  if (!std::regex_search(vtp, m, element)) return {};
  const std::size_t block = vtp.find("<AppendedData encoding=\"raw\">\n_") + 31;
  const std::size_t at = block + std::stoull(m[1].str());
  std::uint64_t bytes = 0;
  std::memcpy(&bytes, vtp.data() + at, sizeof bytes);
  std::vector<T> values(bytes / sizeof(T));
  std::memcpy(values.data(), vtp.data() + at + sizeof bytes, bytes);
  return values;
}

World spinning_grains() {
  World world;
  world.materials.emplace_back();
  const sim::GrainShape grain = sim::make_tetrahedral_grain(1e-3, 2e-3, 2500);
  sim::add_grain(world, grain, 0, Eigen::Vector3d(0, 0, 0.01), Eigen::Quaterniond::Identity(),
                 Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(0, 0, 10));
  sim::add_grain(world, grain, 0, Eigen::Vector3d(0.01, 0, 0.01),
                 Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX())));
  world.time = 0.25;
  return world;
}

TEST(VtkFiles, ParticleVtpHoldsEveryArrayInBinaryWithVertexCells) {
  const World world = spinning_grains();
  const auto dir = test::temp_dir();
  write_particles_vtp(world, dir / "p.vtp");
  const std::string vtp = read_file(dir / "p.vtp");
  EXPECT_NE(vtp.find("NumberOfPoints=\"8\" NumberOfVerts=\"8\""), std::string::npos);
  EXPECT_EQ(vtp.find("format=\"ascii\""), std::string::npos);
  const auto velocity = appended_array<double>(vtp, "velocity");
  const auto orientation = appended_array<double>(vtp, "orientation");
  const auto body = appended_array<std::uint32_t>(vtp, "body");
  const auto time = appended_array<double>(vtp, "TimeValue");
  ASSERT_EQ(velocity.size(), 24u);
  ASSERT_EQ(orientation.size(), 32u);
  ASSERT_EQ(body.size(), 8u);
  ASSERT_EQ(time.size(), 1u);
  EXPECT_EQ(time[0], 0.25);
  for (std::size_t i = 0; i < 8; ++i) {
    const std::uint32_t k = world.particles.body[i];
    EXPECT_EQ(body[i], k);
    const Eigen::Vector3d arm = world.bodies.orientation[k] * world.particles.offset[i];
    const Eigen::Vector3d v = world.bodies.linear_velocity[k] + world.bodies.angular_velocity[k].cross(arm);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(velocity[3 * i + c], v[c]) << i;
    EXPECT_EQ(orientation[4 * i + 3], world.bodies.orientation[k].w()) << i;
  }
}

TEST(VtkFiles, CollectionListsEachOutputWithItsTimeAndATakenUpRunKeepsTheEarlierOnes) {
  const auto dir = test::temp_dir();
  {
    VtpCollection pvd(dir / "run.pvd");
    pvd.add("particles_000000.vtp", 0.0);
    pvd.add("particles_000001.vtp", 0.5);
    pvd.add("particles_000002.vtp", 1.0);
  }
  const std::string written = read_file(dir / "run.pvd");
  EXPECT_NE(written.find("<DataSet timestep=\"0.5\" group=\"\" part=\"0\" file=\"particles_000001.vtp\"/>"),
            std::string::npos);
  VtpCollection resumed(dir / "run.pvd");
  resumed.restore(2);  // the checkpoint was taken after two outputs
  resumed.add("particles_000002.vtp", 1.0);
  EXPECT_EQ(read_file(dir / "run.pvd"), written);
}

}  // namespace
}  // namespace ts::scene
