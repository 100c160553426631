// The host-GPU round-trip counts (gpu/host_sync.h): each call that waits for the GPU is counted once,
// work that is only issued is not, and timer queries are read at the end, not while kernels run.
#include "gpu/host_sync.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/params.h"
#include "shaders/test/bindings.h"

namespace ts::gpu {
namespace {

class HostSync : public ::testing::Test {
 protected:
  Context context;
  ShaderLibrary library;
};

TEST_F(HostSync, EachBufferReadIsOneRoundTripAndUploadsNone) {
  Buffer buffer(64);
  const HostSyncCounts before = host_sync_counts();
  buffer.upload(std::vector<float>(16, 1.0f).data(), 64);
  buffer.fill_zero();
  EXPECT_EQ((host_sync_counts() - before).total(), 0);
  buffer.read<float>(16);
  buffer.read<float>(4, 8);
  buffer.read<float>(0);  // nothing to read, no wait
  const HostSyncCounts made = host_sync_counts() - before;
  EXPECT_EQ(made.reads, 2);
  EXPECT_EQ(made.total(), 2);
}

// Reads go through a staging buffer of at most kReadbackChunkBytes: a larger read comes back whole,
// in one round trip per chunk, also from an offset that puts the chunk boundary mid-array.
TEST_F(HostSync, ReadsLargerThanOneStagingChunkComeBackWholeInOneRoundTripPerChunk) {
  const std::size_t words = kReadbackChunkBytes / sizeof(std::uint32_t) + 1027;
  std::vector<std::uint32_t> pattern(words);
  for (std::size_t i = 0; i < words; ++i) pattern[i] = static_cast<std::uint32_t>(i * 2654435761u) ^ 0x5a5a5a5au;
  const Buffer buffer = Buffer::from<std::uint32_t>(pattern);
  HostSyncCounts before = host_sync_counts();
  EXPECT_EQ(buffer.read<std::uint32_t>(words), pattern);
  EXPECT_EQ((host_sync_counts() - before).reads, 2);
  const std::size_t first = 3, count = words - 5;  // both ends cut, the boundary mid-array
  before = host_sync_counts();
  const auto middle = buffer.read<std::uint32_t>(count, first);
  EXPECT_EQ((host_sync_counts() - before).reads, 2);
  ASSERT_EQ(middle.size(), count);
  EXPECT_TRUE(std::equal(middle.begin(), middle.end(), pattern.begin() + first));
  // A small read after the large ones reuses the staging buffer and reads only what it asks for.
  EXPECT_EQ(buffer.read<std::uint32_t>(2, words - 2), std::vector<std::uint32_t>(pattern.end() - 2, pattern.end()));
}

TEST_F(HostSync, FinishIsCountedOnTheQueueAndTheContext) {
  Queue queue;
  const HostSyncCounts before = host_sync_counts();
  queue.finish();
  context.finish();
  EXPECT_EQ((host_sync_counts() - before).finishes, 2);
}

TEST_F(HostSync, TimerQueriesAreReadOnlyAtTheEnd) {
  Program saxpy = Program::compute(library, "test/saxpy.comp");
  Buffer x(4), y(4);
  x.bind(TS_TEST_SAXPY_X);
  y.bind(TS_TEST_SAXPY_Y);
  ParamBlock<params::SaxpyParams> params;
  params.values = {{1u, 0u, 0u, 0u}, {1.0f, 0.0f, 0.0f, 0.0f}};
  params.bind(TS_TEST_PARAMS);
  Queue queue(/*timings=*/true);
  const HostSyncCounts before = host_sync_counts();
  const int kernels = 600;  // more than the 256 after which timers were once read mid-run
  for (int k = 0; k < kernels; ++k) queue.dispatch_items(saxpy, 1);
  EXPECT_EQ((host_sync_counts() - before).total(), 0);
  const auto timings = queue.timings();
  ASSERT_EQ(timings.size(), 1u);
  EXPECT_EQ(timings[0].calls, static_cast<std::size_t>(kernels));
  const HostSyncCounts made = host_sync_counts() - before;
  EXPECT_EQ(made.query_reads, 1);
  EXPECT_EQ(made.total(), 1);
  queue.timings();  // nothing pending: no second wait
  EXPECT_EQ((host_sync_counts() - before).total(), 1);
}

TEST(HostSyncReport, ListsEachPhaseWithItsRoundTripsPerUnit) {
  HostSyncCounts checks;
  checks.reads = 3;
  const std::string report =
      host_sync_report({{"iterations", {}, 25, "iteration"}, {"checks", checks, 3, "check"}});
  EXPECT_NE(report.find("host-GPU round trips"), std::string::npos) << report;
  EXPECT_NE(report.find("iterations (25)"), std::string::npos) << report;
  EXPECT_NE(report.find("0 per iteration"), std::string::npos) << report;
  EXPECT_NE(report.find("1 per check"), std::string::npos) << report;
}

}  // namespace
}  // namespace ts::gpu
