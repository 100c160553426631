#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <numeric>
#include <vector>

#include "core/error.h"
#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/params.h"
#include "gpu/shader_library.h"
#include "shaders/test/bindings.h"

namespace ts::gpu {
namespace {

TEST(GpuContext, CreatesGl45CoreContextOnSomeEglDevice) {
  Context context;
  EXPECT_FALSE(context.renderer().empty());
  EXPECT_NE(context.version().find("4."), std::string::npos);
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  EXPECT_GE(major * 10 + minor, 45);
  EXPECT_GE(context.limits().max_geometry_output_vertices, 256);
}

// Each context makes its own read-back staging buffer and frees it when it ends: reads work in a
// context made after another one read and was destroyed.
TEST(GpuContext, BufferReadsWorkInEachContextOneAfterAnother) {
  const std::vector<float> values = {1.5f, -2.0f, 3.25f, 4.0f};
  for (int round = 0; round < 3; ++round) {
    Context context;
    const Buffer buffer = Buffer::from<float>(values);
    EXPECT_EQ(buffer.read<float>(4), values) << "round " << round;
    EXPECT_EQ(buffer.read<float>(2, 1), std::vector<float>(values.begin() + 1, values.begin() + 3)) << "round " << round;
  }
}

TEST(GpuContext, EnumerationListsTheChosenDevice) {
  const auto devices = enumerate_devices(true);
  ASSERT_FALSE(devices.empty());
  Context context;
  ASSERT_LT(context.device_index(), static_cast<int>(devices.size()));
  EXPECT_TRUE(devices[static_cast<std::size_t>(context.device_index())].usable);
}

TEST(GpuContext, NonexistentDeviceIsAClearGpuError) {
  ContextOptions options;
  options.device = 999;
  try {
    Context context(options);
    FAIL() << "expected GpuError";
  } catch (const GpuError& e) {
    EXPECT_NE(std::string(e.what()).find("device 999 does not exist"), std::string::npos) << e.what();
  }
}

TEST(GpuQueue, DispatchComputesSaxpyAndReadsBack) {
  Context context;
  ShaderLibrary library;
  Program saxpy = Program::compute(library, "test/saxpy.comp");
  const unsigned n = 1000;  // not a multiple of the work-group size: the bounds check matters
  std::vector<float> x(n), y(n);
  std::iota(x.begin(), x.end(), 0.0f);
  std::fill(y.begin(), y.end(), 1.0f);
  Buffer bx = Buffer::from<float>(x), by = Buffer::from<float>(y);
  bx.bind(TS_TEST_SAXPY_X);
  by.bind(TS_TEST_SAXPY_Y);
  ParamBlock<params::SaxpyParams> params;
  params.values = {{n, 0u, 0u, 0u}, {2.0f, 0.0f, 0.0f, 0.0f}};
  params.bind(TS_TEST_PARAMS);
  Queue queue(/*timings=*/true, /*check_errors=*/true);
  queue.dispatch_items(saxpy, n);
  queue.dispatch_items(saxpy, n);
  const auto result = by.read<float>(n);
  for (unsigned i = 0; i < n; ++i) ASSERT_FLOAT_EQ(result[i], 1.0f + 4.0f * static_cast<float>(i)) << i;
  const auto timings = queue.timings();
  ASSERT_EQ(timings.size(), 1u);
  EXPECT_EQ(timings[0].name, "test/saxpy.comp");
  EXPECT_EQ(timings[0].calls, 2u);
  EXPECT_GE(timings[0].milliseconds, 0.0);
  EXPECT_NE(queue.timing_report().find("test/saxpy.comp"), std::string::npos);
}

// An indirect section: a dry run issues nothing and returns the group counts of its dispatches (the
// plan); with arguments of zeros the dispatches run no work, with the plan copied in they run as
// direct dispatches would.
TEST(GpuQueue, IndirectSectionRunsWhatItsArgumentsSayAndNothingOnZeros) {
  Context context;
  ShaderLibrary library;
  Program saxpy = Program::compute(library, "test/saxpy.comp");
  const unsigned n = 1000;
  std::vector<float> x(n), y(n, 1.0f);
  std::iota(x.begin(), x.end(), 0.0f);
  Buffer bx = Buffer::from<float>(x), by = Buffer::from<float>(y);
  bx.bind(TS_TEST_SAXPY_X);
  by.bind(TS_TEST_SAXPY_Y);
  ParamBlock<params::SaxpyParams> params;
  params.values = {{n, 0u, 0u, 0u}, {2.0f, 0.0f, 0.0f, 0.0f}};
  params.bind(TS_TEST_PARAMS);
  Queue queue(/*timings=*/false, /*check_errors=*/true);
  auto section = [&](const Buffer* args) {
    queue.begin_indirect(args);
    queue.dispatch_items(saxpy, n);
    return queue.end_indirect();
  };
  const auto plan = section(nullptr);
  const auto local = static_cast<std::uint32_t>(saxpy.local_size()[0]);
  ASSERT_EQ(plan.size(), 1u);
  EXPECT_EQ(plan[0], (std::array<std::uint32_t, 4>{(n + local - 1) / local, 1u, 1u, 0u}));
  EXPECT_EQ(by.read<float>(n), y);  // the dry run ran nothing
  Buffer args(16);
  args.fill_zero();
  EXPECT_EQ(section(&args), plan);
  EXPECT_EQ(by.read<float>(n), y);  // zero groups: no work
  args.upload(plan.data(), 16);
  section(&args);
  const auto result = by.read<float>(n);
  for (unsigned i = 0; i < n; ++i) ASSERT_FLOAT_EQ(result[i], 1.0f + 2.0f * static_cast<float>(i)) << i;
}

// A ParamBlock rewritten between two dispatches: the first reads what it was issued with, the second
// the new values, and binding unchanged values again uploads nothing new yet still binds the block.
TEST(GpuParamBlock, EachDispatchReadsTheValuesBoundBeforeIt) {
  Context context;
  ShaderLibrary library;
  Program saxpy = Program::compute(library, "test/saxpy.comp");
  const unsigned n = 300;
  std::vector<float> x(n), y(n, 1.0f);
  std::iota(x.begin(), x.end(), 0.0f);
  Buffer bx = Buffer::from<float>(x), by = Buffer::from<float>(y);
  bx.bind(TS_TEST_SAXPY_X);
  by.bind(TS_TEST_SAXPY_Y);
  ParamBlock<params::SaxpyParams> params, other;
  Queue queue(/*timings=*/false, /*check_errors=*/true);
  params.values = {{n, 0u, 0u, 0u}, {2.0f, 0.0f, 0.0f, 0.0f}};
  params.bind(TS_TEST_PARAMS);
  queue.dispatch_items(saxpy, n);
  params.values.scale.x = 3.0f;
  params.values.count.x = n / 2;  // the second dispatch covers the first half only
  params.bind(TS_TEST_PARAMS);
  queue.dispatch_items(saxpy, n);
  other.values = {{n, 0u, 0u, 0u}, {100.0f, 0.0f, 0.0f, 0.0f}};
  other.bind(TS_TEST_PARAMS);  // takes the slot ...
  params.bind(TS_TEST_PARAMS);  // ... and gives it back, unchanged values: no upload, still bound
  queue.dispatch_items(saxpy, n);
  const auto result = by.read<float>(n);
  for (unsigned i = 0; i < n; ++i) {
    const float expected = 1.0f + (i < n / 2 ? 8.0f : 2.0f) * static_cast<float>(i);
    ASSERT_FLOAT_EQ(result[i], expected) << i;
  }
}

TEST(GpuQueue, GroupGridCoversEveryGroupInRowsNoWiderThanTheLimit) {
  for (const std::size_t max_x : {std::size_t{1}, std::size_t{7}, std::size_t{65535}}) {
    for (const std::size_t groups : {std::size_t{1}, max_x, max_x + 1, 2 * max_x, 3 * max_x - 1, 70 * max_x + 3}) {
      const auto [gx, gy] = Queue::group_grid(groups, max_x);
      EXPECT_LE(gx, max_x) << groups << " groups, limit " << max_x;
      EXPECT_GE(std::size_t{gx} * gy, groups) << groups << " groups, limit " << max_x;
      EXPECT_LT(std::size_t{gx} * (gy - 1), groups) << "a whole row of padding: " << groups << ", " << max_x;
      if (groups <= max_x) {
        EXPECT_EQ(gy, 1u);
      }
    }
  }
}

// Past GL_MAX_COMPUTE_WORK_GROUP_COUNT[0] groups (65535 on llvmpipe) the items go out in rows of a 2D
// grid (shaders/common/dispatch.glsl); each is computed once and the padding past the end touches nothing.
TEST(GpuQueue, ItemsPastTheGroupLimitAlongXAreEachComputedOnce) {
  Context context;
  const std::size_t max_x = static_cast<std::size_t>(context.limits().max_compute_work_group_count[0]);
  const std::size_t local = 64;  // test/saxpy.comp
  if (max_x * local > (std::size_t{1} << 26)) GTEST_SKIP() << "this GPU's x limit (" << max_x << " groups) is too large to pass here";
  ShaderLibrary library;
  Program saxpy = Program::compute(library, "test/saxpy.comp");
  const std::size_t n = max_x * local + 1000;
  std::vector<float> x(n), y(n + 64, -7.0f);  // y's tail past `count`: must stay as it is
  for (std::size_t i = 0; i < n; ++i) x[i] = static_cast<float>(i % 4093);
  std::fill(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(n), 1.0f);
  Buffer bx = Buffer::from<float>(x), by = Buffer::from<float>(y);
  bx.bind(TS_TEST_SAXPY_X);
  by.bind(TS_TEST_SAXPY_Y);
  ParamBlock<params::SaxpyParams> params;
  params.values = {{static_cast<unsigned>(n), 0u, 0u, 0u}, {2.0f, 0.0f, 0.0f, 0.0f}};
  params.bind(TS_TEST_PARAMS);
  Queue queue(/*timings=*/false, /*check_errors=*/true);
  queue.dispatch_items(saxpy, n);
  const auto result = by.read<float>(n + 64);
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(result[i], 1.0f + 2.0f * static_cast<float>(i % 4093)) << i;
  for (std::size_t i = n; i < n + 64; ++i) ASSERT_EQ(result[i], -7.0f) << i;
}

TEST(ShaderLibrary, CompileErrorNamesFileAndLine) {
  Context context;
  const auto dir = std::filesystem::temp_directory_path() / "tetrasand-shader-error-test";
  std::filesystem::create_directories(dir / "bad");
  {
    std::ofstream f(dir / "bad" / "broken.comp");
    f << "#version 450\nlayout(local_size_x = 1) in;\nvoid main() {\n  undeclared_variable = 1.0;\n}\n";
  }
  ShaderLibrary library(dir);
  try {
    Program::compute(library, "bad/broken.comp");
    FAIL() << "expected GpuError";
  } catch (const GpuError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("bad/broken.comp:4"), std::string::npos) << message;
  }
}

// Programs are linked once per context: asking again (another stage, batch item or bench repeat)
// links nothing and hands out the same program; other defines are another program.
TEST(GpuProgramCache, TheSameSourceAskedTwiceInOneContextIsLinkedOnce) {
  Context context;
  ShaderLibrary library;
  const std::size_t before = program_links();
  const Program first = Program::compute(library, "test/saxpy.comp");
  EXPECT_EQ(program_links(), before + 1);
  const Program again = Program::compute(library, "test/saxpy.comp");
  EXPECT_EQ(program_links(), before + 1);
  EXPECT_EQ(again.id(), first.id());
  const Program defined = Program::compute(library, "test/saxpy.comp", {"UNUSED_BY_SAXPY 1"});
  EXPECT_EQ(program_links(), before + 2);
  EXPECT_NE(defined.id(), first.id());
}

// The key is the source itself, so an edited file is a new program, and a new context links its own.
TEST(GpuProgramCache, AnEditedShaderFileAndANewContextAreLinkedAnew) {
  const auto dir = std::filesystem::temp_directory_path() / "tetrasand-program-cache-test";
  std::filesystem::create_directories(dir / "cache");
  auto write = [&](const char* body) {
    std::ofstream f(dir / "cache" / "k.comp");
    f << "#version 450\nlayout(local_size_x = 1) in;\nlayout(std430, binding = 0) buffer B { float v[]; };\n"
      << "void main() { " << body << " }\n";
  };
  write("v[0] = 1.0;");
  ShaderLibrary library(dir);
  const std::size_t before = program_links();
  {
    Context context;
    Program::compute(library, "cache/k.comp");
    Program::compute(library, "cache/k.comp");
    EXPECT_EQ(program_links(), before + 1);
    write("v[0] = 2.0;");
    Program::compute(library, "cache/k.comp");
    EXPECT_EQ(program_links(), before + 2);
  }
  Context fresh;
  Program::compute(library, "cache/k.comp");
  EXPECT_EQ(program_links(), before + 3);
}

TEST(ShaderLibrary, MissingShaderDirectoryIsAClearError) {
  EXPECT_THROW(ShaderLibrary("/nonexistent/tetrasand/shaders"), GpuError);
}

}  // namespace
}  // namespace ts::gpu
