#include "gpu/context.h"

#include <GL/glew.h>
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <string>

#include "core/error.h"
#include "core/log.h"
#include "gpu/gl.h"
#include "gpu/host_sync.h"

namespace ts::gpu {
namespace {

struct EglEntryPoints {
  PFNEGLQUERYDEVICESEXTPROC query_devices = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display = nullptr;
};

EglEntryPoints load_egl_entry_points() {
  EglEntryPoints entry;
  entry.query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  entry.query_device_string =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  entry.get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!entry.query_devices || !entry.get_platform_display) {
    throw GpuError(
        "EGL has no device enumeration (EGL_EXT_device_enumeration / EGL_EXT_platform_device); "
        "install libegl1 and libegl-mesa0 (Mesa) or the GPU vendor's EGL driver");
  }
  return entry;
}

std::vector<EGLDeviceEXT> query_devices(const EglEntryPoints& entry) {
  EGLint count = 0;
  if (!entry.query_devices(0, nullptr, &count) || count <= 0) {
    throw GpuError("EGL lists no devices; install libegl-mesa0 and libgl1-mesa-dri for the llvmpipe software device");
  }
  std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
  entry.query_devices(count, devices.data(), &count);
  devices.resize(static_cast<std::size_t>(count));
  return devices;
}

DeviceDescription describe(const EglEntryPoints& entry, EGLDeviceEXT device, int index) {
  DeviceDescription d;
  d.index = index;
  if (entry.query_device_string) {
    if (const char* ext = entry.query_device_string(device, EGL_EXTENSIONS)) d.extensions = ext;
#ifdef EGL_DRM_DEVICE_FILE_EXT
    if (d.extensions.find("EGL_EXT_device_drm") != std::string::npos) {
      if (const char* node = entry.query_device_string(device, EGL_DRM_DEVICE_FILE_EXT)) d.drm_node = node;
    }
#endif
  }
  d.software = d.extensions.find("EGL_MESA_device_software") != std::string::npos;
  return d;
}

std::string egl_error_text(EGLint code) {
  switch (code) {
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    default: return "EGL error 0x" + [code] {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%x", static_cast<unsigned>(code));
      return std::string(buf);
    }();
  }
}

struct RawContext {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

void destroy(RawContext& raw) {
  if (raw.display == EGL_NO_DISPLAY) return;
  if (raw.context != EGL_NO_CONTEXT && eglGetCurrentContext() == raw.context) release_readback_staging();
  if (raw.context != EGL_NO_CONTEXT) release_program_cache(raw.context);
  eglMakeCurrent(raw.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (raw.context != EGL_NO_CONTEXT) eglDestroyContext(raw.display, raw.context);
  eglTerminate(raw.display);
  raw = {};
}

// Creates a surfaceless GL 4.5 core context on one device and makes it current; throws GpuError.
RawContext create_on(const EglEntryPoints& entry, EGLDeviceEXT device, int index, bool debug) {
  RawContext raw;
  raw.display = entry.get_platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
  EGLint major = 0, minor = 0;
  if (raw.display == EGL_NO_DISPLAY || !eglInitialize(raw.display, &major, &minor)) {
    throw GpuError("EGL device " + std::to_string(index) + ": cannot initialise its display (" +
                   egl_error_text(eglGetError()) + ")");
  }
  try {
    if (!eglBindAPI(EGL_OPENGL_API)) throw GpuError("EGL device " + std::to_string(index) + ": no desktop OpenGL API");
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                        EGL_NONE};
    EGLConfig config = nullptr;
    EGLint config_count = 0;
    if (!eglChooseConfig(raw.display, config_attributes, &config, 1, &config_count) || config_count < 1) {
      throw GpuError("EGL device " + std::to_string(index) + ": no OpenGL-capable config");
    }
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4,
                                         EGL_CONTEXT_MINOR_VERSION, 5,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_CONTEXT_OPENGL_DEBUG, debug ? EGL_TRUE : EGL_FALSE,
                                         EGL_NONE};
    raw.context = eglCreateContext(raw.display, config, EGL_NO_CONTEXT, context_attributes);
    if (raw.context == EGL_NO_CONTEXT) {
      throw GpuError("EGL device " + std::to_string(index) + ": no OpenGL 4.5 core context (" +
                     egl_error_text(eglGetError()) + "); tetrasand needs GL 4.5 (Mesa >= 20 or a recent GPU driver)");
    }
    if (!eglMakeCurrent(raw.display, EGL_NO_SURFACE, EGL_NO_SURFACE, raw.context)) {
      throw GpuError("EGL device " + std::to_string(index) + ": cannot make a surfaceless context current (" +
                     egl_error_text(eglGetError()) + ")");
    }
    // Debian's GLEW is built for GLX and returns GLEW_ERROR_NO_GLX_DISPLAY (4) under EGL although every
    // entry point loads through libglvnd: accept 4 and check a GL 4.5 entry point instead.
    glewExperimental = GL_TRUE;
    const GLenum glew = glewInit();
    if (glew != GLEW_OK && glew != 4) {
      throw GpuError("GLEW could not load OpenGL entry points (error " + std::to_string(glew) + ")");
    }
    if (glDispatchCompute == nullptr || glCreateBuffers == nullptr) {
      throw GpuError("EGL device " + std::to_string(index) + ": OpenGL 4.5 entry points are missing");
    }
    glGetError();  // glewInit may leave GL_INVALID_ENUM behind on core profiles
  } catch (...) {
    destroy(raw);
    throw;
  }
  return raw;
}

int device_from_environment() {
  const char* env = std::getenv("TETRASAND_DEVICE");
  if (!env || !*env) return -1;
  char* end = nullptr;
  const long value = std::strtol(env, &end, 10);
  if (*end != '\0' || value < 0) throw InputError("TETRASAND_DEVICE='" + std::string(env) + "' is not a device index");
  return static_cast<int>(value);
}

void GLAPIENTRY debug_callback(GLenum, GLenum type, GLuint, GLenum severity, GLsizei, const GLchar* message,
                               const void*) {
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
  if (type == GL_DEBUG_TYPE_ERROR) {
    log::warn("GL: {}", message);
  } else {
    log::debug("GL: {}", message);
  }
}

DeviceLimits read_limits() {
  DeviceLimits l;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &l.max_3d_texture_size);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &l.max_texture_layers);
  glGetIntegerv(GL_MAX_GEOMETRY_OUTPUT_VERTICES, &l.max_geometry_output_vertices);
  glGetIntegerv(GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS, &l.max_geometry_total_output_components);
  for (GLuint i = 0; i < 3; ++i) glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, i, &l.max_compute_work_group_count[i]);
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &l.max_texture_size);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, l.max_viewport_dims);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &l.max_framebuffer_size[0]);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_HEIGHT, &l.max_framebuffer_size[1]);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_LAYERS, &l.max_framebuffer_layers);
  glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &l.max_vertex_shader_storage_blocks);
  GLint64 ssbo = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &ssbo);
  l.max_ssbo_bytes = ssbo;
  if (glewIsSupported("GL_NVX_gpu_memory_info")) {
    GLint kb = 0;
    glGetIntegerv(0x9047 /* GL_GPU_MEMORY_INFO_DEDICATED_VIDMEM_NVX */, &kb);
    l.dedicated_memory_kb = kb;
  }
  glGetError();
  return l;
}

std::string gl_string(GLenum name) {
  const auto* text = reinterpret_cast<const char*>(glGetString(name));
  return text ? text : "";
}

}  // namespace

std::vector<DeviceDescription> enumerate_devices(bool probe) {
  const EglEntryPoints entry = load_egl_entry_points();
  const auto devices = query_devices(entry);
  std::vector<DeviceDescription> out;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    DeviceDescription d = describe(entry, devices[i], static_cast<int>(i));
    if (probe) {
      d.probed = true;
      try {
        RawContext raw = create_on(entry, devices[i], d.index, false);
        d.usable = true;
        d.renderer = gl_string(GL_RENDERER);
        d.version = gl_string(GL_VERSION);
        destroy(raw);
      } catch (const GpuError& e) {
        d.problem = e.what();
      }
    }
    out.push_back(std::move(d));
  }
  return out;
}

Context::Context(const ContextOptions& options) : debug_(options.debug) {
  const EglEntryPoints entry = load_egl_entry_points();
  const auto devices = query_devices(entry);
  int wanted = options.device >= 0 ? options.device : device_from_environment();
  if (wanted >= static_cast<int>(devices.size())) {
    throw GpuError("device " + std::to_string(wanted) + " does not exist: EGL lists " +
                   std::to_string(devices.size()) + " device(s); run `tetrasand devices`");
  }
  std::vector<int> order;
  if (wanted >= 0) {
    order.push_back(wanted);
  } else {
    // Hardware first, software (llvmpipe) last.
    for (int pass = 0; pass < 2; ++pass)
      for (std::size_t i = 0; i < devices.size(); ++i)
        if (describe(entry, devices[i], static_cast<int>(i)).software == (pass == 1)) order.push_back(static_cast<int>(i));
  }
  std::string problems;
  for (int index : order) {
    try {
      RawContext raw = create_on(entry, devices[static_cast<std::size_t>(index)], index, debug_);
      display_ = raw.display;
      context_ = raw.context;
      device_index_ = index;
      software_ = describe(entry, devices[static_cast<std::size_t>(index)], index).software;
      break;
    } catch (const GpuError& e) {
      problems += std::string("\n  ") + e.what();
    }
  }
  if (!context_) throw GpuError("no OpenGL 4.5 core context could be created on any EGL device:" + problems);

  renderer_ = gl_string(GL_RENDERER);
  version_ = gl_string(GL_VERSION);
  limits_ = read_limits();
  if (debug_ && glDebugMessageCallback) {
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(debug_callback, nullptr);
  }
  log::info("GPU: {}", summary());
}

Context::~Context() {
  RawContext raw{display_, context_};
  destroy(raw);
}

void Context::finish() const {
  count_finish();
  glFinish();
}

std::string Context::summary() const {
  return renderer_ + " / " + version_ + " (device " + std::to_string(device_index_) +
         (software_ ? ", software" : ", hardware") + ")";
}

}  // namespace ts::gpu
