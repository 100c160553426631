#include "gpu/gl.h"

#include <EGL/egl.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "core/error.h"
#include "core/log.h"
#include "gpu/host_sync.h"

namespace ts::gpu {

namespace {

std::string gl_error_name(GLenum code) {
  switch (code) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return fmt::format("GL error 0x{:x}", code);
  }
}

GLuint compile_stage(const ShaderLibrary& library, GLenum stage, const std::string& relative,
                     const ShaderSource& source) {
  const GLuint shader = glCreateShader(stage);
  const char* text = source.text.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw GpuError("cannot compile shader " + relative + ":\n" +
                   ShaderLibrary::annotate_log(log.c_str(), source, library.root()));
  }
  return shader;
}

GLuint link(const std::vector<GLuint>& shaders, const std::string& name) {
  const GLuint program = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(program, s);
  glLinkProgram(program);
  for (GLuint s : shaders) {
    glDetachShader(program, s);
    glDeleteShader(s);
  }
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    glDeleteProgram(program);
    throw GpuError("cannot link program " + name + ":\n" + log.c_str());
  }
  return program;
}

// The programs each context has linked, by the full source of their stages (includes and defines
// resolved, so a shader file edited on disk is a new key): Program::compute/graphics link each once
// per context. Global, not per thread, so a context destroyed on any thread drops its entry and a
// later context that reuses its handle never sees its program names.
struct ProgramCache {
  std::mutex mutex;
  std::map<EGLContext, std::map<std::string, GLuint>> programs;
  std::atomic<std::size_t> links{0};
};
// Never destroyed: a gpu::Context held in a static (test fixtures, the preview's shared context) is
// destroyed at exit after a function-local static made later would be, and its destructor releases
// its programs here; with a destroyed map that walk never ended (preview tests hung at exit).
ProgramCache& program_cache() {
  static ProgramCache& cache = *new ProgramCache;
  return cache;
}

// The current context's program for `key`, linked by `make` the first time; `name` for the log.
template <typename Make>
GLuint cached_program(const std::string& key, const std::string& name, Make&& make) {
  ProgramCache& cache = program_cache();
  const EGLContext current = eglGetCurrentContext();
  {
    const std::lock_guard lock(cache.mutex);
    const auto& programs = cache.programs[current];
    if (const auto it = programs.find(key); it != programs.end()) return it->second;
  }
  const auto start = std::chrono::steady_clock::now();
  const GLuint program = make();  // GL calls outside the lock: contexts on other threads go on
  ++cache.links;
  // What a cold start costs, program by program (docs/benchmarks/preview.md, "Cold start"): compile
  // and link; a driver that builds machine code on first use (llvmpipe) adds that to the first pass.
  log::debug("gpu: compiled and linked {} in {:.3f} s",
             name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  const std::lock_guard lock(cache.mutex);
  cache.programs[current].emplace(key, program);
  return program;
}

// The staging buffer of the context current on this thread (GL contexts are current per thread):
// host memory by hint (client storage, map-read), the only buffer the host reads directly.
struct ReadbackStaging {
  EGLContext context = EGL_NO_CONTEXT;  // whose buffer name `id` is
  GLuint id = 0;
  std::size_t bytes = 0;
};
thread_local ReadbackStaging staging;

// The staging buffer, holding at least `bytes` (at most kReadbackChunkBytes are asked for).
GLuint readback_staging(std::size_t bytes) {
  const EGLContext current = eglGetCurrentContext();
  // A buffer name of another (possibly destroyed) context means nothing here: forget it, never delete it.
  if (staging.context != current) staging = {current, 0, 0};
  if (staging.id != 0 && staging.bytes >= bytes) return staging.id;
  if (staging.id != 0) glDeleteBuffers(1, &staging.id);
  // Doubling keeps the number of reallocations logarithmic in the largest read.
  const std::size_t size = std::min(kReadbackChunkBytes, std::max({bytes, 2 * staging.bytes, std::size_t{4096}}));
  staging = {current, 0, 0};
  glCreateBuffers(1, &staging.id);
  glNamedBufferStorage(staging.id, static_cast<GLsizeiptr>(size), nullptr, GL_MAP_READ_BIT | GL_CLIENT_STORAGE_BIT);
  if (glGetError() == GL_OUT_OF_MEMORY) {
    glDeleteBuffers(1, &staging.id);
    staging.id = 0;
    throw GpuError(fmt::format("out of memory allocating a {:.1f} MiB read-back buffer", size / 1048576.0));
  }
  staging.bytes = size;
  return staging.id;
}

}  // namespace

void release_program_cache(void* egl_context) {
  ProgramCache& cache = program_cache();
  const std::lock_guard lock(cache.mutex);
  const auto it = cache.programs.find(static_cast<EGLContext>(egl_context));
  if (it == cache.programs.end()) return;
  // Not current: the names cannot be deleted here, but go with the context itself.
  if (eglGetCurrentContext() == it->first)
    for (const auto& [key, program] : it->second) glDeleteProgram(program);
  cache.programs.erase(it);
}

std::size_t program_links() { return program_cache().links.load(); }

void release_readback_staging() {
  if (staging.context != eglGetCurrentContext()) return;  // another context's: not ours to free
  if (staging.id != 0) glDeleteBuffers(1, &staging.id);
  staging = {};
}

void check_gl(const std::string& what) {
  const GLenum code = glGetError();
  if (code != GL_NO_ERROR) {
    while (glGetError() != GL_NO_ERROR) {
    }
    throw GpuError(gl_error_name(code) + " in " + what);
  }
}

// ---------------------------------------------------------------------------------------------- Buffer

Buffer::Buffer(std::size_t bytes, const void* data, GLbitfield flags) : bytes_(bytes) {
  glCreateBuffers(1, &id_);
  // Zero-sized storage is illegal; keep one word so empty scenes still bind something valid.
  glNamedBufferStorage(id_, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 4)), bytes ? data : nullptr,
                       flags | GL_DYNAMIC_STORAGE_BIT);
  if (glGetError() == GL_OUT_OF_MEMORY) {
    glDeleteBuffers(1, &id_);
    id_ = 0;
    throw GpuError(fmt::format("out of GPU memory allocating a buffer of {:.1f} MiB", bytes / 1048576.0));
  }
}

Buffer::~Buffer() {
  if (id_) glDeleteBuffers(1, &id_);
}

Buffer::Buffer(Buffer&& other) noexcept
    : id_(std::exchange(other.id_, 0)), bytes_(std::exchange(other.bytes_, 0)) {}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    if (id_) glDeleteBuffers(1, &id_);
    id_ = std::exchange(other.id_, 0);
    bytes_ = std::exchange(other.bytes_, 0);
  }
  return *this;
}

void Buffer::upload(const void* data, std::size_t bytes, std::size_t offset) {
  if (offset + bytes > bytes_) throw GpuError(fmt::format("buffer upload of {} bytes at {} overruns {} bytes", bytes, offset, bytes_));
  if (bytes) glNamedBufferSubData(id_, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
}

void Buffer::download(void* data, std::size_t bytes, std::size_t offset) const {
  if (offset + bytes > bytes_) throw GpuError(fmt::format("buffer read of {} bytes at {} overruns {} bytes", bytes, offset, bytes_));
  if (bytes == 0) return;
  // Kernel writes become visible to the copy (a buffer update) through this barrier.
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  auto* out = static_cast<std::byte*>(data);
  for (std::size_t done = 0; done < bytes;) {
    const std::size_t chunk = std::min(bytes - done, kReadbackChunkBytes);
    const GLuint stage = readback_staging(chunk);
    glCopyNamedBufferSubData(id_, stage, static_cast<GLintptr>(offset + done), 0, static_cast<GLsizeiptr>(chunk));
    count_read();
    glGetNamedBufferSubData(stage, 0, static_cast<GLsizeiptr>(chunk), out + done);
    done += chunk;
  }
}

void Buffer::fill_zero() {
  const GLuint zero = 0;
  glClearNamedBufferData(id_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
}

void Buffer::bind(GLuint binding, GLenum target) const { glBindBufferBase(target, binding, id_); }

// --------------------------------------------------------------------------------------------- Program

Program Program::compute(const ShaderLibrary& library, const std::string& relative,
                         const std::vector<std::string>& defines) {
  const ShaderSource source = library.load(relative, defines);
  Program p;
  p.name_ = relative;
  p.id_ = cached_program("comp\n" + source.text, relative, [&] {
    return link({compile_stage(library, GL_COMPUTE_SHADER, relative, source)}, relative);
  });
  return p;
}

Program Program::graphics(const ShaderLibrary& library, const std::string& vertex, const std::string& geometry,
                          const std::string& fragment, const std::vector<std::string>& defines) {
  std::vector<std::pair<GLenum, std::string>> stages{{GL_VERTEX_SHADER, vertex}};
  if (!geometry.empty()) stages.emplace_back(GL_GEOMETRY_SHADER, geometry);
  stages.emplace_back(GL_FRAGMENT_SHADER, fragment);
  std::vector<ShaderSource> sources;
  std::string key;
  for (const auto& [stage, relative] : stages) {
    sources.push_back(library.load(relative, defines));
    key += fmt::format("stage {:x} {}\n", stage, sources.back().text.size()) + sources.back().text;
  }
  Program p;
  p.name_ = vertex + "+" + (geometry.empty() ? "" : geometry + "+") + fragment;
  p.id_ = cached_program(key, p.name_, [&] {
    std::vector<GLuint> shaders;
    for (std::size_t s = 0; s < stages.size(); ++s)
      shaders.push_back(compile_stage(library, stages[s].first, stages[s].second, sources[s]));
    return link(shaders, p.name_);
  });
  return p;
}

// The cache owns the program (released with its context): a handle only forgets it.
Program::~Program() = default;

Program::Program(Program&& other) noexcept
    : id_(std::exchange(other.id_, 0)), name_(std::move(other.name_)) {}

Program& Program::operator=(Program&& other) noexcept {
  if (this != &other) {
    id_ = std::exchange(other.id_, 0);
    name_ = std::move(other.name_);
  }
  return *this;
}

void Program::use() const { glUseProgram(id_); }

std::array<int, 3> Program::local_size() const {
  std::array<int, 3> size{1, 1, 1};
  glGetProgramiv(id_, GL_COMPUTE_WORK_GROUP_SIZE, size.data());
  return size;
}

// ----------------------------------------------------------------------------------------------- Queue

Queue::~Queue() {
  for (const auto& p : pending_) {
    glDeleteQueries(1, &p.start);
    glDeleteQueries(1, &p.stop);
  }
  if (!spare_queries_.empty()) glDeleteQueries(static_cast<GLsizei>(spare_queries_.size()), spare_queries_.data());
}

void Queue::add_host_seconds(const std::string& name, double seconds) {
  for (auto& [known, total] : host_seconds_) {
    if (known == name) {
      total += seconds;
      return;
    }
  }
  host_seconds_.emplace_back(name, seconds);
}

double Queue::host_seconds(const std::string& name) const {
  for (const auto& [known, total] : host_seconds_)
    if (known == name) return total;
  return 0.0;
}

void Queue::begin_indirect(const Buffer* args) {
  if (indirect_) throw std::logic_error("Queue::begin_indirect: an indirect section is already open");
  indirect_ = true;
  indirect_args_ = args;
  indirect_plan_.clear();
  if (args) glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, args->id());
}

std::vector<std::array<std::uint32_t, 4>> Queue::end_indirect() {
  if (!indirect_) throw std::logic_error("Queue::end_indirect without begin_indirect");
  if (indirect_args_ && indirect_args_->bytes() < indirect_plan_.size() * 16) {
    throw std::logic_error("Queue::end_indirect: more dispatches than the argument buffer has rows");
  }
  indirect_ = false;
  indirect_args_ = nullptr;
  return std::move(indirect_plan_);
}

void Queue::dispatch(const Program& program, std::uint32_t gx, std::uint32_t gy, std::uint32_t gz, GLbitfield barrier) {
  if (gx == 0 || gy == 0 || gz == 0) return;
  if (indirect_) {
    const std::size_t row = indirect_plan_.size();
    indirect_plan_.push_back({gx, gy, gz, 0u});
    if (!indirect_args_) return;  // a dry run
    if (indirect_args_->bytes() < (row + 1) * 16) return;  // end_indirect reports it
  }
  begin(program.name());
  program.use();
  if (indirect_) {
    glDispatchComputeIndirect(static_cast<GLintptr>(16 * (indirect_plan_.size() - 1)));
  } else {
    glDispatchCompute(gx, gy, gz);
  }
  if (barrier) glMemoryBarrier(barrier);
  end(program.name());
  if (check_errors_) check("kernel " + program.name());
}

std::pair<std::uint32_t, std::uint32_t> Queue::group_grid(std::size_t groups, std::size_t max_x) {
  if (groups <= max_x) return {static_cast<std::uint32_t>(groups), 1u};
  // Rows as even as the limit allows: fewer padding groups in the last row than full rows of max_x.
  const std::size_t rows = (groups + max_x - 1) / max_x;
  return {static_cast<std::uint32_t>((groups + rows - 1) / rows), static_cast<std::uint32_t>(rows)};
}

void Queue::dispatch_groups(const Program& program, std::size_t groups, GLbitfield barrier) {
  if (groups == 0) return;
  // Queried once: a state query per dispatch is a driver call in the innermost loop.
  if (max_groups_[0] == 0) {
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &max_groups_[0]);
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 1, &max_groups_[1]);
  }
  const auto [gx, gy] = group_grid(groups, static_cast<std::size_t>(max_groups_[0]));
  // Past both limits a dispatch is a GL error that leaves the buffers as they were: stop instead.
  if (gy > static_cast<std::uint32_t>(max_groups_[1])) {
    throw GpuError(fmt::format("dispatch of {} needs {} work groups, above this GPU's limit of {} x {}", program.name(),
                               groups, max_groups_[0], max_groups_[1]));
  }
  dispatch(program, gx, gy, 1, barrier);
}

void Queue::dispatch_items(const Program& program, std::size_t items, GLbitfield barrier) {
  const std::size_t local = static_cast<std::size_t>(program.local_size()[0]);
  dispatch_groups(program, (items + local - 1) / local, barrier);
}

void Queue::check(const std::string& what) const { check_gl(what); }

void Queue::finish() const {
  count_finish();
  glFinish();
}

void Queue::begin(const std::string& name) {
  if (!timings_) return;
  Pending p;
  p.name = name;
  if (spare_queries_.size() < 2) {
    GLuint ids[64];
    glGenQueries(64, ids);
    spare_queries_.insert(spare_queries_.end(), ids, ids + 64);
  }
  p.start = spare_queries_.back();
  spare_queries_.pop_back();
  p.stop = spare_queries_.back();
  spare_queries_.pop_back();
  glQueryCounter(p.start, GL_TIMESTAMP);
  pending_.push_back(std::move(p));
}

void Queue::end(const std::string& name) {
  if (!timings_) return;
  auto it = std::find_if(pending_.rbegin(), pending_.rend(), [&](const Pending& p) { return p.name == name; });
  if (it == pending_.rend()) return;
  glQueryCounter(it->stop, GL_TIMESTAMP);
  // Reading results waits for the GPU, so they are read at the end (timings()). Long runs (a
  // simulation dispatches millions of kernels) bound the queries in flight: past kMaxPendingTimers
  // the results the GPU has already written are taken without waiting, and only when there are
  // none does the host wait.
  if (pending_.size() >= kMaxPendingTimers && resolve(false) == 0) resolve(true);
}

std::size_t Queue::resolve(bool wait) {
  if (pending_.empty()) return 0;
  if (wait) count_query_read();
  std::size_t done = 0;
  for (; done < pending_.size(); ++done) {
    const Pending& p = pending_[done];
    if (!wait) {  // queries finish in the order they were issued: stop at the first still running
      GLint available = 0;
      glGetQueryObjectiv(p.stop, GL_QUERY_RESULT_AVAILABLE, &available);
      if (!available) break;
    }
    GLuint64 t0 = 0, t1 = 0;
    glGetQueryObjectui64v(p.start, GL_QUERY_RESULT, &t0);
    glGetQueryObjectui64v(p.stop, GL_QUERY_RESULT, &t1);
    auto total = std::find_if(totals_.begin(), totals_.end(), [&](const KernelTiming& k) { return k.name == p.name; });
    if (total == totals_.end()) {
      totals_.push_back({p.name, 0, 0.0});
      total = totals_.end() - 1;
    }
    total->calls += 1;
    total->milliseconds += static_cast<double>(t1 - t0) * 1e-6;
    spare_queries_.push_back(p.start);
    spare_queries_.push_back(p.stop);
  }
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(done));
  return done;
}

std::vector<KernelTiming> Queue::timings() {
  resolve(true);
  return totals_;
}

std::string Queue::timing_report() {
  const auto all = timings();
  double sum = 0.0;
  for (const auto& k : all) sum += k.milliseconds;
  std::string out = fmt::format("{:<40} {:>8} {:>12} {:>10}\n", "GPU kernel", "calls", "total ms", "share");
  for (const auto& k : all) {
    out += fmt::format("{:<40} {:>8} {:>12.3f} {:>9.1f}%\n", k.name, k.calls, k.milliseconds,
                       sum > 0 ? 100.0 * k.milliseconds / sum : 0.0);
  }
  out += fmt::format("{:<40} {:>8} {:>12.3f}\n", "total", "", sum);
  return out;
}

}  // namespace ts::gpu
