#include <gtest/gtest.h>

#include <fstream>
#include <numeric>
#include <vector>

#include "core/error.h"
#include "gpu/context.h"
#include "gpu/gl.h"
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
  saxpy.set("a", 2.0f);
  saxpy.set("count", n);
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

TEST(ShaderLibrary, MissingShaderDirectoryIsAClearError) {
  EXPECT_THROW(ShaderLibrary("/nonexistent/tetrasand/shaders"), GpuError);
}

}  // namespace
}  // namespace ts::gpu
