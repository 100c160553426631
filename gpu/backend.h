#pragma once
// The one rule for where a stage runs, CPU or GPU, shared by every command (sdf, sample, preview, sim), and
// the one-line report each prints of its choice. Auto: the CPU on a software renderer (Mesa llvmpipe runs the
// GL kernels on the same cores as the CPU twins, plus a fixed cost per dispatch, so the twins are faster
// there: docs/architecture.md, "Which engine runs") or without a GL context; the GPU on a hardware device.
// Every stage has both paths (the preview's CPU renderer since issue 45: preview/cpu_renderer.h).
#include <optional>
#include <string>
#include <string_view>

namespace ts::gpu {

class Context;

enum class Backend { Auto, Gpu, Cpu };

// "auto", "gpu", "cpu": the --backend spellings.
const char* backend_name(Backend backend);
// The inverse of backend_name; nullopt for any other text.
std::optional<Backend> parse_backend(std::string_view text);

// What the rule looks at: whether there is a GL device and whether it is a software renderer.
enum class DeviceKind { None, Software, Hardware };
struct Device {
  DeviceKind kind = DeviceKind::None;
  std::string renderer;  // "llvmpipe", "NVIDIA H100 80GB HBM3": the GL renderer without its build details
};
// The device of `context`; kind None for a null one.
Device describe(const Context* context);

// Gpu or Cpu: `requested` unless it is Auto, which takes the CPU on a software renderer or without a device
// and the GPU on a hardware one. has_cpu_path false (a stage with only a GPU path): Auto takes the GPU
// whatever the device; a requested Cpu is kept, for the caller to refuse.
Backend resolve_backend(Backend requested, DeviceKind device, bool has_cpu_path = true);
Backend resolve_backend(Backend requested, const Context* context, bool has_cpu_path = true);

// Why `chosen` runs, the parenthesis of backend_line: "asked for", "auto: no GL context", "auto: the GL
// device is llvmpipe, a software renderer; --backend gpu forces the GPU", "auto: the GL device is NVIDIA H100
// 80GB HBM3, a hardware GPU", "auto: there is no CPU path yet; the GL device is ...".
std::string backend_reason(Backend requested, Backend chosen, const Device& device, bool has_cpu_path = true);
// The choice in one line, the same form for every command, without a newline:
//   "backend: cpu (auto: the GL device is llvmpipe, a software renderer;
//   --backend gpu forces the GPU)" "backend: gpu, scan conversion (asked for)"
// `what` names what runs there (empty: nothing) after a comma; `note` follows the reason after a semicolon.
std::string backend_line(Backend requested, Backend chosen, const Device& device, bool has_cpu_path = true,
                         std::string_view what = {}, std::string_view note = {});

}  // namespace ts::gpu
