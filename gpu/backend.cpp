#include "gpu/backend.h"

#include <fmt/format.h>

#include "gpu/context.h"

namespace ts::gpu {

const char* backend_name(Backend backend) {
  switch (backend) {
    case Backend::Gpu:
      return "gpu";
    case Backend::Cpu:
      return "cpu";
    case Backend::Auto:
      break;
  }
  return "auto";
}

std::optional<Backend> parse_backend(std::string_view text) {
  for (const Backend b : {Backend::Auto, Backend::Gpu, Backend::Cpu})
    if (text == backend_name(b)) return b;
  return std::nullopt;
}

Device describe(const Context* context) {
  if (context == nullptr) return {};
  const std::string& renderer = context->renderer();
  // "llvmpipe (LLVM 15.0.6, 256 bits)" -> "llvmpipe"
  return {context->software() ? DeviceKind::Software : DeviceKind::Hardware,
          renderer.substr(0, renderer.find(" ("))};
}

Backend resolve_backend(Backend requested, DeviceKind device, bool has_cpu_path) {
  if (requested != Backend::Auto) return requested;
  if (!has_cpu_path) return Backend::Gpu;
  return device == DeviceKind::Hardware ? Backend::Gpu : Backend::Cpu;
}

Backend resolve_backend(Backend requested, const Context* context, bool has_cpu_path) {
  return resolve_backend(requested, describe(context).kind, has_cpu_path);
}

std::string backend_reason(Backend requested, Backend chosen, const Device& device, bool has_cpu_path) {
  if (requested != Backend::Auto) return "asked for";
  if (device.kind == DeviceKind::None) return "auto: no GL context";
  const std::string is =
      fmt::format("the GL device is {}, a {}", device.renderer,
                  device.kind == DeviceKind::Software ? "software renderer" : "hardware GPU");
  if (!has_cpu_path) return "auto: there is no CPU path yet; " + is;
  if (chosen == Backend::Cpu) return fmt::format("auto: {}; --backend gpu forces the GPU", is);
  return "auto: " + is;
}

std::string backend_line(Backend requested, Backend chosen, const Device& device, bool has_cpu_path,
                         std::string_view what, std::string_view note) {
  return fmt::format("backend: {}{}{} ({}{}{})", backend_name(chosen), what.empty() ? "" : ", ", what,
                     backend_reason(requested, chosen, device, has_cpu_path), note.empty() ? "" : "; ", note);
}

}  // namespace ts::gpu
