#pragma once
// Headless OpenGL 4.5 core context on an EGL device display (EGL_EXT_platform_device): no window, no
// X server. The default device is the first hardware GPU, else Mesa's llvmpipe (software), so every
// shader also runs on machines without a GPU. TETRASAND_DEVICE=N or --device N picks another.
#include <string>
#include <vector>

namespace ts::gpu {

struct DeviceDescription {
  int index = -1;
  bool software = false;   // Mesa's llvmpipe/softpipe (EGL_MESA_device_software)
  std::string extensions;  // EGL device extensions
  std::string drm_node;    // /dev/dri/... when the device exposes one
  // Filled only when probed (a GL 4.5 context was created on the device):
  bool probed = false;
  bool usable = false;
  std::string renderer, version, problem;
};

// Every EGL device; with probe=true a short-lived context is created on each to read its renderer.
std::vector<DeviceDescription> enumerate_devices(bool probe);

struct ContextOptions {
  int device = -1;     // -1: TETRASAND_DEVICE if set, else first hardware device, else software
  bool debug = false;  // KHR_debug output; GL errors after each dispatch become exceptions
};

struct DeviceLimits {
  int max_3d_texture_size = 0;
  int max_texture_layers = 0;                // layers of a 2D array texture
  int max_framebuffer_layers = 0;            // layers of a layered render target
  int max_geometry_output_vertices = 0;
  int max_geometry_total_output_components = 0;
  int max_compute_work_group_count[3] = {0, 0, 0};
  int max_texture_size = 0;                  // texels per side of a 2D texture
  int max_viewport_dims[2] = {0, 0};         // pixels
  int max_framebuffer_size[2] = {0, 0};      // pixels, width and height
  int max_vertex_shader_storage_blocks = 0;  // storage buffers one vertex shader may read
  long long max_ssbo_bytes = 0;
  long long dedicated_memory_kb = 0;  // 0 when the driver does not say (NVX_gpu_memory_info)
};

// Owns the EGL display and context and keeps it current on the creating thread.
// Throws ts::GpuError with one clear sentence when no GL 4.5 core context can be made.
class Context {
 public:
  explicit Context(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& renderer() const { return renderer_; }
  const std::string& version() const { return version_; }
  int device_index() const { return device_index_; }
  bool software() const { return software_; }
  bool debug() const { return debug_; }
  const DeviceLimits& limits() const { return limits_; }
  // "llvmpipe (LLVM 15.0.6, 256 bits) / 4.5 (Core Profile) Mesa 22.3.6 (device 0, software)"
  std::string summary() const;
  // Blocks until the GPU has finished all work issued on this context (benchmarks time with it).
  void finish() const;

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
  int device_index_ = -1;
  bool software_ = false;
  bool debug_ = false;
  std::string renderer_, version_;
  DeviceLimits limits_;
};

}  // namespace ts::gpu
