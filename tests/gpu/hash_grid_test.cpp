#include "gpu/hash_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gpu/context.h"

namespace ts::gpu {
namespace {

class GpuGrid : public ::testing::Test {
 protected:
  Context context;
  ShaderLibrary library;
  Queue queue{false, true};
};

TEST_F(GpuGrid, PrefixScanMatchesCpuAtBlockBoundariesAndAcrossLevels) {
  PrefixScan scan(library);
  std::mt19937 rng(7);
  for (std::uint32_t n : {1u, 511u, 512u, 513u, 262145u + 1000u}) {
    std::vector<std::uint32_t> values(n);
    for (auto& v : values) v = rng() % 7;
    Buffer buffer = Buffer::from<std::uint32_t>(values);
    scan.run(queue, buffer, n);
    const auto gpu = buffer.read<std::uint32_t>(n);
    std::uint32_t sum = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      ASSERT_EQ(gpu[i], sum) << "n=" << n << " i=" << i;
      sum += values[i];
    }
  }
}

// A scan with more 512-value blocks than the GPU's work groups along x (65535 on llvmpipe): its first
// level goes out as a 2D grid of groups, whose padding groups must write no block sum.
TEST_F(GpuGrid, PrefixScanPastTheGroupLimitAlongXMatchesCpu) {
  const std::size_t max_x = static_cast<std::size_t>(context.limits().max_compute_work_group_count[0]);
  if (max_x * 512 > (std::size_t{1} << 26)) GTEST_SKIP() << "this GPU's x limit (" << max_x << " groups) is too large to pass here";
  const auto n = static_cast<std::uint32_t>(max_x * 512 + 1000);
  std::vector<std::uint32_t> values(n);
  std::mt19937 rng(11);
  for (auto& v : values) v = rng() % 3;
  Buffer buffer = Buffer::from<std::uint32_t>(values);
  PrefixScan scan(library);
  scan.run(queue, buffer, n);
  const auto gpu = buffer.read<std::uint32_t>(n);
  std::uint32_t sum = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    ASSERT_EQ(gpu[i], sum) << "i=" << i;
    sum += values[i];
  }
}

std::uint32_t cpu_hash(int x, int y, int z, std::uint32_t table) {
  return ((static_cast<std::uint32_t>(x) * 73856093u) ^ (static_cast<std::uint32_t>(y) * 19349663u) ^
          (static_cast<std::uint32_t>(z) * 83492791u)) & (table - 1u);
}

TEST_F(GpuGrid, EveryCellHoldsExactlyItsParticlesInIndexOrder) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  const std::uint32_t n = 5000;
  std::vector<float> positions(4 * n);
  for (std::uint32_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) positions[4 * i + static_cast<std::uint32_t>(a)] = u(rng);
  // A dense clump: far more particles in one cell than the thesis's 4-per-texel cap.
  for (std::uint32_t i = 0; i < 100; ++i) positions[4 * i] = positions[4 * i + 1] = positions[4 * i + 2] = 0.01f;
  Buffer buffer = Buffer::from<float>(positions);
  HashGrid grid(library);
  const float cell = 0.25f;
  grid.build(queue, buffer, n, cell);
  const std::uint32_t table = grid.table_size();
  EXPECT_GE(table, 2 * n);
  std::vector<std::uint32_t> count(table), start(table), sorted(n);
  // Read back through the bindings the neighbour kernels use.
  grid.bind();
  GLint id = 0;
  glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 2, &id);
  glGetNamedBufferSubData(static_cast<GLuint>(id), 0, table * 4, count.data());
  glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 4, &id);
  glGetNamedBufferSubData(static_cast<GLuint>(id), 0, table * 4, start.data());
  glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 5, &id);
  glGetNamedBufferSubData(static_cast<GLuint>(id), 0, n * 4, sorted.data());
  std::vector<std::uint32_t> expected_count(table, 0);
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto h = cpu_hash(static_cast<int>(std::floor(positions[4 * i] / cell)),
                            static_cast<int>(std::floor(positions[4 * i + 1] / cell)),
                            static_cast<int>(std::floor(positions[4 * i + 2] / cell)), table);
    ++expected_count[h];
  }
  EXPECT_EQ(count, expected_count);
  for (std::uint32_t c = 0; c < table; ++c) {
    for (std::uint32_t k = 0; k < count[c]; ++k) {
      const std::uint32_t i = sorted[start[c] + k];
      ASSERT_EQ(cpu_hash(static_cast<int>(std::floor(positions[4 * i] / cell)),
                         static_cast<int>(std::floor(positions[4 * i + 1] / cell)),
                         static_cast<int>(std::floor(positions[4 * i + 2] / cell)), table),
                c);
      if (k > 0) {
        ASSERT_LT(sorted[start[c] + k - 1], i);
      }
    }
  }
}

}  // namespace
}  // namespace ts::gpu
