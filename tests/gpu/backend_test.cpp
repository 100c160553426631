// The one backend rule (gpu/backend.h): auto takes the CPU on a software renderer or without a GL context and
// the GPU on a hardware device; a forced choice is kept; a stage with no CPU path takes the GPU under auto;
// every command's line reads the same.
#include "gpu/backend.h"

#include <gtest/gtest.h>

#include "gpu/context.h"

namespace ts::gpu {
namespace {

TEST(BackendRule, AutoTakesTheCpuOnASoftwareRendererOrWithoutAContextAndTheGpuOnHardware) {
  EXPECT_EQ(resolve_backend(Backend::Auto, DeviceKind::Software), Backend::Cpu);
  EXPECT_EQ(resolve_backend(Backend::Auto, DeviceKind::None), Backend::Cpu);
  EXPECT_EQ(resolve_backend(Backend::Auto, DeviceKind::Hardware), Backend::Gpu);
  EXPECT_EQ(resolve_backend(Backend::Auto, static_cast<const Context*>(nullptr)), Backend::Cpu);
}

TEST(BackendRule, ForcedChoicesAreKeptOnEveryDevice) {
  for (const DeviceKind device : {DeviceKind::None, DeviceKind::Software, DeviceKind::Hardware}) {
    EXPECT_EQ(resolve_backend(Backend::Gpu, device), Backend::Gpu);
    EXPECT_EQ(resolve_backend(Backend::Cpu, device), Backend::Cpu);
    EXPECT_EQ(resolve_backend(Backend::Cpu, device, false),
              Backend::Cpu);  // for the caller to refuse
    EXPECT_EQ(resolve_backend(Backend::Auto, device, false),
              Backend::Gpu);  // no CPU path
  }
}

TEST(BackendRule, AutoOnARealContextFollowsWhetherItIsASoftwareRenderer) {
  const Context context;
  EXPECT_EQ(resolve_backend(Backend::Auto, &context), context.software() ? Backend::Cpu : Backend::Gpu);
  EXPECT_EQ(describe(&context).kind, context.software() ? DeviceKind::Software : DeviceKind::Hardware);
  EXPECT_EQ(describe(&context).renderer.find(" ("), std::string::npos) << describe(&context).renderer;
}

TEST(BackendRule, SpellingsRoundTripAndOthersAreRefused) {
  for (const Backend b : {Backend::Auto, Backend::Gpu, Backend::Cpu})
    EXPECT_EQ(parse_backend(backend_name(b)), b);
  EXPECT_EQ(parse_backend("tpu"), std::nullopt);
  EXPECT_EQ(parse_backend("GPU"), std::nullopt);
  EXPECT_EQ(parse_backend(""), std::nullopt);
}

TEST(BackendRule, EveryChoiceReadsInTheSameOneLineForm) {
  const Device llvmpipe{DeviceKind::Software, "llvmpipe"}, h100{DeviceKind::Hardware, "NVIDIA H100"};
  EXPECT_EQ(
      backend_line(Backend::Auto, Backend::Cpu, llvmpipe),
      "backend: cpu (auto: the GL device is llvmpipe, a software renderer; --backend gpu forces the GPU)");
  EXPECT_EQ(backend_line(Backend::Auto, Backend::Gpu, h100),
            "backend: gpu (auto: the GL device is NVIDIA H100, a hardware GPU)");
  EXPECT_EQ(backend_line(Backend::Gpu, Backend::Gpu, llvmpipe, true, "scan conversion"),
            "backend: gpu, scan conversion (asked for)");
  EXPECT_EQ(backend_line(Backend::Auto, Backend::Cpu, Device{}), "backend: cpu (auto: no GL context)");
  EXPECT_EQ(backend_line(Backend::Auto, Backend::Gpu, llvmpipe, false, {}, "a note"),
            "backend: gpu (auto: there is no CPU path yet; the GL device is llvmpipe, a software renderer; a "
            "note)");
}

}  // namespace
}  // namespace ts::gpu
