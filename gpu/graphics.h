#pragma once
// The rasterising half of the GL 4.5 layer (gpu/gl.h is the compute half): textures, framebuffers,
// vertex arrays, draw calls and scoped fixed-function state, for the passes that draw (the SDF scan
// conversion, the preview). Every object owns one GL name, is move-only and frees the name when it
// is destroyed, also during unwinding. Draws go through gpu::Queue, so --timings names them and
// --gl-debug checks them; a StateScope puts back the state it changed when it ends.
#include <GL/glew.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gpu/gl.h"

namespace ts::gpu {

namespace detail {

// One GL object name and the function that deletes it. Move-only; 0 when empty or moved from.
class GlName {
 public:
  using Deleter = void (*)(GLuint);
  GlName() = default;
  GlName(GLuint id, Deleter deleter) : id_(id), deleter_(deleter) {}
  ~GlName() { reset(); }
  GlName(GlName&& other) noexcept;
  GlName& operator=(GlName&& other) noexcept;
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;

  GLuint get() const { return id_; }

 private:
  void reset();
  GLuint id_ = 0;
  Deleter deleter_ = nullptr;
};

}  // namespace detail

// Immutable storage for one mip level of a 2D, 2D-array or 3D texture. `what` names it in errors
// ("preview albedo buffer"). Sizes are in texels; depth() is the layer count of an array, 1 in 2D.
class Texture {
 public:
  Texture() = default;  // empty: id() == 0
  // `format` is a sized internal format (GL_RGBA32F, GL_DEPTH_COMPONENT32F, ...). GpuError naming
  // the texture and its size when the GPU is out of memory.
  static Texture create_2d(GLenum format, int width, int height, std::string what);
  static Texture create_2d_array(GLenum format, int width, int height, int layers, std::string what);
  static Texture create_3d(GLenum format, int width, int height, int depth, std::string what);

  GLuint id() const { return name_.get(); }
  bool empty() const { return id() == 0; }
  GLenum target() const { return target_; }
  GLenum format() const { return format_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int depth() const { return depth_; }
  const std::string& what() const { return what_; }
  // Bytes of storage; 0 when empty or for a format missing from graphics.cpp's table.
  std::size_t bytes() const;

  // Minification and magnification `filter` (GL_NEAREST, GL_LINEAR), clamp-to-edge on every axis.
  void set_sampling(GLenum filter);
  // For a sampler2DShadow: texture() returns `func`(reference, stored depth), e.g. GL_LEQUAL.
  void set_depth_compare(GLenum func);

  // Writes layers (slices) [first, first + count) from host memory, x fastest, then y, then layer,
  // as `pixel_format`/`type` (GL_RED/GL_FLOAT, ...). count < 0: up to the last layer.
  void upload(const void* pixels, GLenum pixel_format, GLenum type, int first = 0, int count = -1);
  // The same from a GPU buffer, tightly packed from its start, copied on the GPU (a pixel-unpack
  // upload: no host round trip). Writes by kernels need GL_PIXEL_BUFFER_BARRIER_BIT before it. 2D only.
  void upload_from(const Buffer& pixels, GLenum pixel_format, GLenum type);
  // Reads layers [first, first + count) into `pixels` (`bytes` long), in the same order.
  void read(void* pixels, std::size_t bytes, GLenum pixel_format, GLenum type, int first = 0,
            int count = -1) const;
  // Copies this texture's layers [0, count) into `destination`'s layers [first, first + count), on
  // the GPU; the formats must be copy-compatible. count < 0: all of this texture's layers.
  void copy_to(const Texture& destination, int first = 0, int count = -1) const;

  // Binds this texture to a texture unit (the shader names the unit with layout(binding = ...)).
  void bind_unit(GLuint unit) const;
  static void unbind_unit(GLuint unit);

 private:
  static Texture create(GLenum target, GLenum format, std::array<int, 3> size, std::string what);
  int layer_count(int first, int count, const char* operation) const;

  detail::GlName name_;
  GLenum target_ = 0, format_ = 0;
  int width_ = 0, height_ = 0, depth_ = 0;
  std::string what_;
};

// Binds all layers of level 0 of a texture to an image unit for the lifetime of this object.
class ImageBinding {
 public:
  // access: GL_READ_ONLY, GL_WRITE_ONLY or GL_READ_WRITE; the image format is the texture's.
  ImageBinding(GLuint unit, const Texture& texture, GLenum access);
  ~ImageBinding();
  ImageBinding(const ImageBinding&) = delete;
  ImageBinding& operator=(const ImageBinding&) = delete;

 private:
  GLuint unit_;
  GLenum access_, format_;
};

// A framebuffer object: textures attached by reference (they must outlive it), the draw buffers
// that receive the fragment outputs, and a completeness check that says what is wrong.
class Framebuffer {
 public:
  Framebuffer() = default;  // empty: id() == 0
  // No attachments; fragment output 0 goes to colour attachment 0 (GL's default draw buffer).
  explicit Framebuffer(std::string what);

  GLuint id() const { return name_.get(); }
  // Level 0 of `texture`, every layer of it (a layered target for arrays and 3D textures).
  void attach_color(int index, const Texture& texture);
  void attach_depth(const Texture& texture);
  // Fragment outputs 0 .. count - 1 go to colour attachments 0 .. count - 1; 0: none (depth only).
  void set_draw_buffers(int count);
  // GpuError naming the framebuffer and the problem: a draw buffer without a colour attachment
  // (GL accepts that and drops the output), or GL's incompleteness status by name, with what is
  // attached.
  void check_complete() const;

  void clear_color(int index, const std::array<float, 4>& rgba);
  void clear_depth(float depth);

 private:
  std::string describe_attachments() const;

  detail::GlName name_;
  std::string what_;
  std::vector<std::string> colors_;  // colour attachment i: the texture's name; empty: none
  std::string depth_;                // the depth texture's name; empty: none
  int draw_buffers_ = 1;
};

// A vertex array object. The passes here read their vertices from buffers in the shaders, so it
// holds at most an element (index) buffer.
class VertexArray {
 public:
  VertexArray() = default;  // empty: id() == 0
  static VertexArray create();
  GLuint id() const { return name_.get(); }
  // 32-bit indices for draw_elements; the buffer must outlive the vertex array's use.
  void set_element_buffer(const Buffer& indices);

 private:
  detail::GlName name_;
};

// Draws `count` vertices from `first` with `program`, primitives `mode` (GL_TRIANGLES, ...), the
// vertices made in the vertex shader from gl_VertexID. Timed under `timer` unless it is empty (for
// a pass the caller times as a whole); a GL error becomes a GpuError when the queue checks errors.
void draw_arrays(Queue& queue, const Program& program, GLenum mode, std::size_t first, std::size_t count,
                 const std::string& timer = {});
// The same with `count` 32-bit indices from index `first` of the bound vertex array's element buffer.
void draw_elements(Queue& queue, const Program& program, GLenum mode, std::size_t first, std::size_t count,
                   const std::string& timer = {});

// Fixed-function state and bindings set for a scope: each setter remembers the value it replaces
// the first time, and the destructor puts every remembered value back, also when an exception
// passes. Scopes nest. The current program is not part of it: every draw and dispatch binds its own.
class StateScope {
 public:
  StateScope() = default;
  ~StateScope();
  StateScope(const StateScope&) = delete;
  StateScope& operator=(const StateScope&) = delete;

  // Binds `target` for drawing and reading.
  StateScope& framebuffer(const Framebuffer& target);
  // The viewport [pixels], from the lower left corner.
  StateScope& viewport(int width, int height);
  StateScope& vertex_array(const VertexArray& vertices);
  // Depth test with `func` (GL_LESS, ...), depth writes on or off.
  StateScope& depth_test(GLenum func, bool write = true);
  StateScope& no_depth_test();
  // Culls `face` (GL_FRONT, GL_BACK).
  StateScope& cull(GLenum face);
  StateScope& no_cull();
  StateScope& no_blend();

 private:
  struct Depth {
    GLboolean enabled;
    GLint func;
    GLboolean write;
  };
  struct Culling {
    GLboolean enabled;
    GLint face;
  };
  void save_depth();
  void save_culling();

  std::optional<std::array<GLint, 2>> framebuffers_;  // draw, read
  std::optional<std::array<GLint, 4>> viewport_;
  std::optional<GLint> vertex_array_;
  std::optional<Depth> depth_;
  std::optional<Culling> culling_;
  std::optional<GLboolean> blend_;
};

// What the raster pipeline did over a span of draws (GL_ARB_pipeline_statistics_query, core in GL 4.6):
// geometry-shader invocations and emitted primitives and fragment-shader invocations, to hold against a
// model of the work a pass should make (the SDF scan conversion's prisms, sdf/prism_model.h). Reading a
// span's counts waits for the GPU, so a pass counts only when asked (--timings).
struct PipelineCounts {
  std::uint64_t geometry_invocations = 0;
  std::uint64_t geometry_primitives = 0;
  std::uint64_t fragment_invocations = 0;
};

class PipelineStatistics {
 public:
  // Whether the current context has the queries (llvmpipe and NVIDIA's drivers do).
  static bool available();
  // GpuError when !available().
  PipelineStatistics();
  ~PipelineStatistics();
  PipelineStatistics(const PipelineStatistics&) = delete;
  PipelineStatistics& operator=(const PipelineStatistics&) = delete;

  // Counts the draws issued between begin() and end(); end() waits for them and adds their counts.
  void begin();
  void end();
  const PipelineCounts& counts() const { return counts_; }

 private:
  std::array<GLuint, 3> queries_{};
  bool active_ = false;
  PipelineCounts counts_;
};

}  // namespace ts::gpu
