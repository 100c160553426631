#include "gpu/graphics.h"

#include <fmt/format.h>

#include <climits>
#include <utility>

#include "core/error.h"
#include "gpu/host_sync.h"

namespace ts::gpu {

namespace {

void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }

std::size_t bytes_per_texel(GLenum format) {
  switch (format) {
    case GL_R16F:
      return 2;
    case GL_R32F:
    case GL_RGBA8:
    case GL_DEPTH_COMPONENT32F:
      return 4;
    case GL_RGBA16F:
      return 8;
    case GL_RGBA32F:
      return 16;
    default:
      return 0;
  }
}

std::string framebuffer_status_name(GLenum status) {
  switch (status) {
    case GL_FRAMEBUFFER_UNDEFINED:
      return "GL_FRAMEBUFFER_UNDEFINED";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT:
      return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT (an attachment is unusable)";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT:
      return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT (nothing is attached)";
    case GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER:
      return "GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER";
    case GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER:
      return "GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER";
    case GL_FRAMEBUFFER_UNSUPPORTED:
      return "GL_FRAMEBUFFER_UNSUPPORTED (this GPU cannot render to these formats)";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE:
      return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    case GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS:
      return "GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS (layered and single-layer attachments mixed)";
    default:
      return fmt::format("status 0x{:x}", status);
  }
}

GLsizei to_sizei(std::size_t n, const std::string& what) {
  if (n > static_cast<std::size_t>(INT_MAX))
    throw GpuError(fmt::format("{} of {} items is too large", what, n));
  return static_cast<GLsizei>(n);
}

}  // namespace

// ---------------------------------------------------------------------------------------------- GlName

detail::GlName::GlName(GlName&& other) noexcept
    : id_(std::exchange(other.id_, 0)), deleter_(other.deleter_) {}

detail::GlName& detail::GlName::operator=(GlName&& other) noexcept {
  if (this != &other) {
    reset();
    id_ = std::exchange(other.id_, 0);
    deleter_ = other.deleter_;
  }
  return *this;
}

void detail::GlName::reset() {
  if (id_) deleter_(id_);
  id_ = 0;
}

// --------------------------------------------------------------------------------------------- Texture

Texture Texture::create(GLenum target, GLenum format, std::array<int, 3> size, std::string what) {
  GLuint id = 0;
  glCreateTextures(target, 1, &id);
  Texture t;
  t.name_ = detail::GlName(id, delete_texture);
  t.target_ = target;
  t.format_ = format;
  t.width_ = size[0];
  t.height_ = size[1];
  t.depth_ = size[2];
  t.what_ = std::move(what);
  if (target == GL_TEXTURE_2D) {
    glTextureStorage2D(id, 1, format, t.width_, t.height_);
  } else {
    glTextureStorage3D(id, 1, format, t.width_, t.height_, t.depth_);
  }
  if (glGetError() == GL_OUT_OF_MEMORY) {
    throw GpuError(fmt::format("out of GPU memory for texture '{}' ({} x {} x {} texels, {:.1f} MiB)",
                               t.what_, t.width_, t.height_, t.depth_, t.bytes() / 1048576.0));
  }
  return t;
}

Texture Texture::create_2d(GLenum format, int width, int height, std::string what) {
  return create(GL_TEXTURE_2D, format, {width, height, 1}, std::move(what));
}

Texture Texture::create_2d_array(GLenum format, int width, int height, int layers, std::string what) {
  return create(GL_TEXTURE_2D_ARRAY, format, {width, height, layers}, std::move(what));
}

Texture Texture::create_3d(GLenum format, int width, int height, int depth, std::string what) {
  return create(GL_TEXTURE_3D, format, {width, height, depth}, std::move(what));
}

std::size_t Texture::bytes() const {
  if (empty()) return 0;
  return bytes_per_texel(format_) * static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) *
         static_cast<std::size_t>(depth_);
}

void Texture::set_sampling(GLenum filter) {
  glTextureParameteri(id(), GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
  glTextureParameteri(id(), GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
  glTextureParameteri(id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (target_ == GL_TEXTURE_3D) glTextureParameteri(id(), GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
}

void Texture::set_depth_compare(GLenum func) {
  glTextureParameteri(id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(id(), GL_TEXTURE_COMPARE_FUNC, static_cast<GLint>(func));
}

int Texture::layer_count(int first, int count, const char* operation) const {
  const int n = count < 0 ? depth_ - first : count;
  if (first < 0 || n < 0 || first + n > depth_) {
    throw GpuError(fmt::format("{} of layers [{}, {}) of texture '{}' overruns its {} layers", operation,
                               first, first + n, what_, depth_));
  }
  return n;
}

void Texture::upload(const void* pixels, GLenum pixel_format, GLenum type, int first, int count) {
  const int n = layer_count(first, count, "upload");
  if (target_ == GL_TEXTURE_2D) {
    glTextureSubImage2D(id(), 0, 0, 0, width_, height_, pixel_format, type, pixels);
  } else {
    glTextureSubImage3D(id(), 0, 0, 0, first, width_, height_, n, pixel_format, type, pixels);
  }
}

void Texture::upload_from(const Buffer& pixels, GLenum pixel_format, GLenum type) {
  if (target_ != GL_TEXTURE_2D) throw GpuError(what_ + ": uploads from a buffer are for 2D textures");
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pixels.id());
  glTextureSubImage2D(id(), 0, 0, 0, width_, height_, pixel_format, type, nullptr);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
}

void Texture::read(void* pixels, std::size_t bytes, GLenum pixel_format, GLenum type, int first,
                   int count) const {
  const int n = layer_count(first, count, "read");
  count_read();
  glGetTextureSubImage(id(), 0, 0, 0, first, width_, height_, n, pixel_format, type,
                       to_sizei(bytes, "texture read"), pixels);
}

void Texture::copy_to(const Texture& destination, int first, int count) const {
  const int n = layer_count(0, count, "copy");
  destination.layer_count(first, n, "copy");
  glCopyImageSubData(id(), target_, 0, 0, 0, 0, destination.id(), destination.target_, 0, 0, 0, first, width_,
                     height_, n);
}

void Texture::bind_unit(GLuint unit) const { glBindTextureUnit(unit, id()); }

void Texture::unbind_unit(GLuint unit) { glBindTextureUnit(unit, 0); }

// ---------------------------------------------------------------------------------------- ImageBinding

ImageBinding::ImageBinding(GLuint unit, const Texture& texture, GLenum access)
    : unit_(unit), access_(access), format_(texture.format()) {
  glBindImageTexture(unit_, texture.id(), 0, GL_TRUE, 0, access_, format_);
}

ImageBinding::~ImageBinding() { glBindImageTexture(unit_, 0, 0, GL_TRUE, 0, access_, format_); }

// ----------------------------------------------------------------------------------------- Framebuffer

Framebuffer::Framebuffer(std::string what) : what_(std::move(what)) {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  name_ = detail::GlName(id, delete_framebuffer);
}

void Framebuffer::attach_color(int index, const Texture& texture) {
  glNamedFramebufferTexture(id(), GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index), texture.id(), 0);
  if (colors_.size() <= static_cast<std::size_t>(index)) colors_.resize(static_cast<std::size_t>(index) + 1);
  colors_[static_cast<std::size_t>(index)] = texture.what();
}

void Framebuffer::attach_depth(const Texture& texture) {
  glNamedFramebufferTexture(id(), GL_DEPTH_ATTACHMENT, texture.id(), 0);
  depth_ = texture.what();
}

void Framebuffer::set_draw_buffers(int count) {
  draw_buffers_ = count;
  if (count == 0) {
    glNamedFramebufferDrawBuffer(id(), GL_NONE);
    return;
  }
  std::vector<GLenum> buffers(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    buffers[static_cast<std::size_t>(i)] = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
  glNamedFramebufferDrawBuffers(id(), count, buffers.data());
}

std::string Framebuffer::describe_attachments() const {
  std::string out;
  for (std::size_t i = 0; i < colors_.size(); ++i) {
    if (!colors_[i].empty()) out += fmt::format("{}colour {} '{}'", out.empty() ? "" : ", ", i, colors_[i]);
  }
  if (!depth_.empty()) out += fmt::format("{}depth '{}'", out.empty() ? "" : ", ", depth_);
  return out.empty() ? "nothing attached" : "attached: " + out;
}

void Framebuffer::check_complete() const {
  for (int i = 0; i < draw_buffers_; ++i) {
    if (static_cast<std::size_t>(i) >= colors_.size() || colors_[static_cast<std::size_t>(i)].empty()) {
      throw GpuError(
          fmt::format("framebuffer '{}' is incomplete: draw buffer {} has no colour attachment {} ({})",
                      what_, i, i, describe_attachments()));
    }
  }
  const GLenum status = glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw GpuError(fmt::format("framebuffer '{}' is incomplete: {} ({})", what_,
                               framebuffer_status_name(status), describe_attachments()));
  }
}

void Framebuffer::clear_color(int index, const std::array<float, 4>& rgba) {
  glClearNamedFramebufferfv(id(), GL_COLOR, index, rgba.data());
}

void Framebuffer::clear_depth(float depth) { glClearNamedFramebufferfv(id(), GL_DEPTH, 0, &depth); }

// ----------------------------------------------------------------------------------------- VertexArray

VertexArray VertexArray::create() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  VertexArray v;
  v.name_ = detail::GlName(id, delete_vertex_array);
  return v;
}

void VertexArray::set_element_buffer(const Buffer& indices) {
  glVertexArrayElementBuffer(id(), indices.id());
}

// ----------------------------------------------------------------------------------------------- Draws

namespace {

template <typename F>
void issue_draw(Queue& queue, const Program& program, const std::string& timer, F&& draw) {
  program.use();
  if (timer.empty()) {
    draw();
  } else {
    queue.timed(timer, draw);
  }
  if (queue.checks_errors()) check_gl("draw with " + program.name());
}

}  // namespace

void draw_arrays(Queue& queue, const Program& program, GLenum mode, std::size_t first, std::size_t count,
                 const std::string& timer) {
  const GLint start = to_sizei(first, "draw start");
  const GLsizei n = to_sizei(count, "draw");
  issue_draw(queue, program, timer, [&] { glDrawArrays(mode, start, n); });
}

void draw_elements(Queue& queue, const Program& program, GLenum mode, std::size_t first, std::size_t count,
                   const std::string& timer) {
  const GLsizei n = to_sizei(count, "indexed draw");
  // The offset of the first index into the element buffer, passed as a pointer (GL's convention).
  const void* offset = reinterpret_cast<const void*>(first * sizeof(GLuint));
  issue_draw(queue, program, timer, [&] { glDrawElements(mode, n, GL_UNSIGNED_INT, offset); });
}

// ------------------------------------------------------------------------------------------ StateScope

namespace {

void set_enabled(GLenum capability, GLboolean enabled) {
  if (enabled) {
    glEnable(capability);
  } else {
    glDisable(capability);
  }
}

}  // namespace

StateScope::~StateScope() {
  if (blend_) set_enabled(GL_BLEND, *blend_);
  if (culling_) {
    set_enabled(GL_CULL_FACE, culling_->enabled);
    glCullFace(static_cast<GLenum>(culling_->face));
  }
  if (depth_) {
    set_enabled(GL_DEPTH_TEST, depth_->enabled);
    glDepthFunc(static_cast<GLenum>(depth_->func));
    glDepthMask(depth_->write);
  }
  if (vertex_array_) glBindVertexArray(static_cast<GLuint>(*vertex_array_));
  if (viewport_) glViewport((*viewport_)[0], (*viewport_)[1], (*viewport_)[2], (*viewport_)[3]);
  if (framebuffers_) {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>((*framebuffers_)[0]));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>((*framebuffers_)[1]));
  }
}

StateScope& StateScope::framebuffer(const Framebuffer& target) {
  if (!framebuffers_) {
    std::array<GLint, 2> bound{};
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound[0]);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &bound[1]);
    framebuffers_ = bound;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, target.id());
  return *this;
}

StateScope& StateScope::viewport(int width, int height) {
  if (!viewport_) {
    std::array<GLint, 4> box{};
    glGetIntegerv(GL_VIEWPORT, box.data());
    viewport_ = box;
  }
  glViewport(0, 0, width, height);
  return *this;
}

StateScope& StateScope::vertex_array(const VertexArray& vertices) {
  if (!vertex_array_) {
    GLint bound = 0;
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &bound);
    vertex_array_ = bound;
  }
  glBindVertexArray(vertices.id());
  return *this;
}

void StateScope::save_depth() {
  if (depth_) return;
  Depth saved{glIsEnabled(GL_DEPTH_TEST), 0, GL_TRUE};
  glGetIntegerv(GL_DEPTH_FUNC, &saved.func);
  glGetBooleanv(GL_DEPTH_WRITEMASK, &saved.write);
  depth_ = saved;
}

StateScope& StateScope::depth_test(GLenum func, bool write) {
  save_depth();
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(func);
  glDepthMask(write ? GL_TRUE : GL_FALSE);
  return *this;
}

StateScope& StateScope::no_depth_test() {
  save_depth();
  glDisable(GL_DEPTH_TEST);
  return *this;
}

void StateScope::save_culling() {
  if (culling_) return;
  Culling saved{glIsEnabled(GL_CULL_FACE), 0};
  glGetIntegerv(GL_CULL_FACE_MODE, &saved.face);
  culling_ = saved;
}

StateScope& StateScope::cull(GLenum face) {
  save_culling();
  glEnable(GL_CULL_FACE);
  glCullFace(face);
  return *this;
}

StateScope& StateScope::no_cull() {
  save_culling();
  glDisable(GL_CULL_FACE);
  return *this;
}

StateScope& StateScope::no_blend() {
  if (!blend_) blend_ = glIsEnabled(GL_BLEND);
  glDisable(GL_BLEND);
  return *this;
}

// ---------------------------------------------------------------------------------- PipelineStatistics

namespace {

constexpr std::array<GLenum, 3> kPipelineTargets = {GL_GEOMETRY_SHADER_INVOCATIONS,
                                                    GL_GEOMETRY_SHADER_PRIMITIVES_EMITTED_ARB,
                                                    GL_FRAGMENT_SHADER_INVOCATIONS_ARB};

}  // namespace

bool PipelineStatistics::available() {
  return glewIsSupported("GL_ARB_pipeline_statistics_query") || GLEW_VERSION_4_6;
}

PipelineStatistics::PipelineStatistics() {
  if (!available()) throw GpuError("this GL device has no pipeline statistics queries (GL_ARB_pipeline_statistics_query)");
  glGenQueries(static_cast<GLsizei>(queries_.size()), queries_.data());
}

PipelineStatistics::~PipelineStatistics() {
  if (active_) {
    for (GLenum target : kPipelineTargets) glEndQuery(target);
  }
  glDeleteQueries(static_cast<GLsizei>(queries_.size()), queries_.data());
}

void PipelineStatistics::begin() {
  if (active_) throw Error(ExitCode::Internal, "PipelineStatistics::begin while counting");
  for (std::size_t i = 0; i < queries_.size(); ++i) glBeginQuery(kPipelineTargets[i], queries_[i]);
  active_ = true;
}

void PipelineStatistics::end() {
  if (!active_) throw Error(ExitCode::Internal, "PipelineStatistics::end without begin");
  for (GLenum target : kPipelineTargets) glEndQuery(target);
  active_ = false;
  std::array<GLuint64, 3> values{};
  for (std::size_t i = 0; i < queries_.size(); ++i) glGetQueryObjectui64v(queries_[i], GL_QUERY_RESULT, &values[i]);
  counts_.geometry_invocations += values[0];
  counts_.geometry_primitives += values[1];
  counts_.fragment_invocations += values[2];
}

}  // namespace ts::gpu
