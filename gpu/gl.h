#pragma once
// A thin layer over OpenGL 4.5 (direct state access): buffers, programs, and a queue that dispatches
// compute kernels by name with explicit memory barriers, reads buffers back, and times each kernel
// with GPU timestamp queries when asked (--timings). Everything GPU-side in tetrasand goes through it.
#include <GL/glew.h>

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gpu/shader_library.h"

namespace ts::gpu {

// The most one read back moves through the staging buffer at a time; larger reads go in chunks,
// so the staging buffer (one per context, grown on demand) never holds more than this.
inline constexpr std::size_t kReadbackChunkBytes = std::size_t{64} << 20;

// Frees the current context's staging buffer; called by Context while its GL context is still
// current, before it is destroyed. A no-op when none was made.
void release_readback_staging();

// Programs are linked once per context and kept: Program::compute and Program::graphics look their
// stages' full source up in the current context's program cache and link only what it lacks, so a
// second scan conversion (or batch item, or bench repeat) in the same process compiles nothing.
// Frees `egl_context`'s cached programs (deleted if it is current, else left to go with it); called
// by Context before the context is destroyed.
void release_program_cache(void* egl_context);
// Programs linked in this process so far, every context together (tests check the cache with it).
std::size_t program_links();

// A shader storage / general-purpose GL buffer. Move-only.
class Buffer {
 public:
  Buffer() = default;
  explicit Buffer(std::size_t bytes, const void* data = nullptr, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
  template <typename T>
  static Buffer from(std::span<const T> items) {
    return Buffer(items.size_bytes(), items.data());
  }
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  GLuint id() const { return id_; }
  std::size_t bytes() const { return bytes_; }
  void upload(const void* data, std::size_t bytes, std::size_t offset = 0);
  template <typename T>
  void upload(std::span<const T> items, std::size_t first = 0) {
    upload(items.data(), items.size_bytes(), first * sizeof(T));
  }
  // Reads [offset, offset + bytes) back: the GPU copies it into the context's host-side staging
  // buffer, the host reads that (one round trip per kReadbackChunkBytes). A buffer read directly is
  // one the driver may move to host memory for good, after which every kernel that writes it does so
  // over the bus: NVIDIA's driver did so to the scan conversion's band buffers on the first device run.
  void download(void* data, std::size_t bytes, std::size_t offset = 0) const;
  template <typename T>
  std::vector<T> read(std::size_t count, std::size_t first = 0) const {
    std::vector<T> out(count);
    if (count) download(out.data(), count * sizeof(T), first * sizeof(T));
    return out;
  }
  void fill_zero();
  void bind(GLuint binding, GLenum target = GL_SHADER_STORAGE_BUFFER) const;

 private:
  GLuint id_ = 0;
  std::size_t bytes_ = 0;
};

// A linked program: one compute kernel, or a vertex[/geometry]/fragment pipeline. A handle to the
// context's cached program (see release_program_cache): valid while the context lives. Move-only.
class Program {
 public:
  Program() = default;
  // Compiles shaders/<relative> (a .comp file). Throws GpuError naming the file and line.
  static Program compute(const ShaderLibrary& library, const std::string& relative,
                         const std::vector<std::string>& defines = {});
  static Program graphics(const ShaderLibrary& library, const std::string& vertex, const std::string& geometry,
                          const std::string& fragment, const std::vector<std::string>& defines = {});
  ~Program();
  Program(Program&& other) noexcept;
  Program& operator=(Program&& other) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  GLuint id() const { return id_; }
  const std::string& name() const { return name_; }
  void use() const;
  // No by-name uniform setters: a kernel's parameters are a struct of shaders/common/params.h in a
  // uniform block, uploaded through gpu::ParamBlock (gpu/params.h).
  // Work-group size declared by a compute kernel (layout(local_size_x = ...)).
  std::array<int, 3> local_size() const;

 private:
  GLuint id_ = 0;
  std::string name_;
};

// Per-kernel GPU times, accumulated over a run.
struct KernelTiming {
  std::string name;
  std::size_t calls = 0;
  double milliseconds = 0.0;
};

// Issues work in order and owns the timer queries. One per context and stage is fine.
class Queue {
 public:
  explicit Queue(bool timings = false, bool check_errors = false) : timings_(timings), check_errors_(check_errors) {}
  ~Queue();
  Queue(const Queue&) = delete;
  Queue& operator=(const Queue&) = delete;

  // Dispatches `groups` work groups of `program`, then issues glMemoryBarrier(barrier) so the next
  // kernel sees this one's writes. barrier = 0 for none (the caller batches barriers itself).
  void dispatch(const Program& program, std::uint32_t groups_x, std::uint32_t groups_y = 1,
                std::uint32_t groups_z = 1, GLbitfield barrier = GL_SHADER_STORAGE_BARRIER_BIT);
  // `groups` work groups numbered 0..groups-1 by dispatch_group() (shaders/common/dispatch.glsl):
  // one row along x, or rows of the GPU's largest x count (GL_MAX_COMPUTE_WORK_GROUP_COUNT[0], 65535
  // on llvmpipe) stacked along y when there are more, the last row padded with groups past the end.
  void dispatch_groups(const Program& program, std::size_t groups, GLbitfield barrier = GL_SHADER_STORAGE_BARRIER_BIT);
  // Enough groups of the program's local size to cover `items` threads, numbered by dispatch_item().
  void dispatch_items(const Program& program, std::size_t items, GLbitfield barrier = GL_SHADER_STORAGE_BARRIER_BIT);
  // The (x, y) grid dispatch_groups uses for `groups` when at most `max_x` fit along x.
  static std::pair<std::uint32_t, std::uint32_t> group_grid(std::size_t groups, std::size_t max_x);
  // GPU-decided work: the dispatches issued between begin_indirect and end_indirect take their group
  // counts from `args` (one 16-byte row per dispatch, in issue order: x, y, z, unused) through
  // glDispatchComputeIndirect, so a kernel run before them decides, with no host read, whether they
  // run: it copies each row of the plan in, or writes zeros. With args = nullptr nothing is issued
  // and the dispatches are only recorded (a dry run that makes the plan). end_indirect returns the
  // group counts each dispatch would have had directly: the plan.
  void begin_indirect(const Buffer* args);
  std::vector<std::array<std::uint32_t, 4>> end_indirect();
  // Times arbitrary GL work (draw calls, copies) under `name`.
  // The host's wall time in each name's sections is kept whether or not timings are on.
  template <typename F>
  void timed(const std::string& name, F&& work) {
    const auto start = std::chrono::steady_clock::now();
    begin(name);
    work();
    end(name);
    add_host_seconds(name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  // Host wall time spent in timed(name, ...) sections so far [s] (0 for a name never timed).
  double host_seconds(const std::string& name) const;
  // Blocks until the GPU has run everything issued (a host round trip, counted in gpu/host_sync.h).
  void finish() const;
  bool timings_enabled() const { return timings_; }
  // Whether each kernel (and each draw of gpu/graphics.h) is followed by a GL error check.
  bool checks_errors() const { return check_errors_; }
  // Timer queries in flight before those already done are read (and, if none is, the host waits).
  static constexpr std::size_t kMaxPendingTimers = 65536;
  // Reads outstanding queries (one host round trip) and returns totals per kernel, in first-use order.
  std::vector<KernelTiming> timings();
  // A table for --timings.
  std::string timing_report();

 private:
  void begin(const std::string& name);
  void end(const std::string& name);
  void check(const std::string& what) const;
  void add_host_seconds(const std::string& name, double seconds);
  // Reads the pending queries, all of them (waiting for the GPU: a host round trip), or with
  // wait = false those already done. Returns how many were read.
  std::size_t resolve(bool wait);

  struct Pending {
    std::string name;
    GLuint start = 0, stop = 0;
  };
  bool timings_;
  bool check_errors_;
  std::vector<Pending> pending_;
  std::vector<GLuint> spare_queries_;
  std::vector<KernelTiming> totals_;
  bool indirect_ = false;
  const Buffer* indirect_args_ = nullptr;                 // null: a dry run (record only)
  std::vector<std::array<std::uint32_t, 4>> indirect_plan_;  // the rows of this indirect section so far
  std::vector<std::pair<std::string, double>> host_seconds_;  // per timed() name, in first-use order
  GLint max_groups_[2] = {0, 0};  // GL_MAX_COMPUTE_WORK_GROUP_COUNT along x and y, 0 until first needed
};

// Throws GpuError with `what` when glGetError reports an error.
void check_gl(const std::string& what);

}  // namespace ts::gpu
