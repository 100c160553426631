// `tetrasand devices`: what EGL sees, what each device gives, and which one a run would pick.
#include <fmt/format.h>

#include "app/commands.h"
#include "core/error.h"
#include "gpu/context.h"

namespace ts::app {

Runner add_devices_command(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand("devices", "List EGL devices and the OpenGL renderer tetrasand would use");
  return [cmd, &global] {
    (void)cmd;
    const auto devices = gpu::enumerate_devices(/*probe=*/true);
    for (const auto& d : devices) {
      fmt::print("device {}: {}{}\n", d.index, d.software ? "software" : "hardware",
                 d.drm_node.empty() ? "" : " (" + d.drm_node + ")");
      if (d.usable) {
        fmt::print("  renderer: {}\n  version:  {}\n", d.renderer, d.version);
      } else {
        fmt::print("  unusable: {}\n", d.problem);
      }
    }
    gpu::ContextOptions options;
    options.device = global.device;
    gpu::Context context(options);
    fmt::print("chosen: device {}: {}\n", context.device_index(), context.summary());
    const auto& l = context.limits();
    fmt::print("limits: 2D texture {} (arrays of {} layers), 3D texture {}, framebuffer {} x {} x {} layers, geometry output "
               "{} vertices / {} components, SSBO {} MiB\n",
               l.max_texture_size, l.max_texture_layers, l.max_3d_texture_size, l.max_framebuffer_size[0],
               l.max_framebuffer_size[1], l.max_framebuffer_layers, l.max_geometry_output_vertices,
               l.max_geometry_total_output_components, l.max_ssbo_bytes / 1048576);
    return 0;
  };
}

}  // namespace ts::app
