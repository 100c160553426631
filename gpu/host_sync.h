#pragma once
// Host-GPU round trips: every call through which the CPU waits for the GPU or reads its memory bumps
// one of these counts (gpu/gl.cpp, gpu/graphics.cpp, gpu/context.cpp are the only places that make
// such calls). Each one drains the GPU's queue of work, so a loop that should run on the GPU alone
// (sim steps between outputs, sampler iterations between convergence checks) must leave them as they
// were; --timings prints them per phase and tests assert them.
#include <cstdint>
#include <string>
#include <vector>

namespace ts::gpu {

struct HostSyncCounts {
  std::int64_t reads = 0;     // buffer or texture read back (glGetNamedBufferSubData, glGetTextureSubImage)
  std::int64_t finishes = 0;  // glFinish
  std::int64_t fence_waits = 0;  // glClientWaitSync (none in the tree today)
  std::int64_t query_reads = 0;  // resolves of pending timer queries (each waits for the newest of them)

  std::int64_t total() const { return reads + finishes + fence_waits + query_reads; }
  HostSyncCounts& operator+=(const HostSyncCounts& other);
  friend HostSyncCounts operator-(HostSyncCounts a, const HostSyncCounts& b);
  friend bool operator==(const HostSyncCounts&, const HostSyncCounts&) = default;
};

// The counts of this thread since it started (GL contexts are current per thread). Take the
// difference of two calls to count a phase.
HostSyncCounts host_sync_counts();

// Called by the gpu layer next to the GL call that waits.
void count_read();
void count_finish();
void count_fence_wait();
void count_query_read();

// A phase of a run and the round trips made in it, for the --timings table: `units` times `unit` (a
// sim step, a relaxation iteration, a convergence check; units = 0: no per-unit column).
struct HostSyncPhase {
  std::string name;
  HostSyncCounts counts;
  std::int64_t units = 0;
  std::string unit;
};

// "host-GPU round trips" table: one row per phase with its counts and the round trips per unit.
std::string host_sync_report(const std::vector<HostSyncPhase>& phases);

// Adds the round trips made while it lives to `into` (a phase's running total).
class HostSyncScope {
 public:
  explicit HostSyncScope(HostSyncCounts& into) : into_(into), start_(host_sync_counts()) {}
  ~HostSyncScope() { into_ += host_sync_counts() - start_; }
  HostSyncScope(const HostSyncScope&) = delete;
  HostSyncScope& operator=(const HostSyncScope&) = delete;

 private:
  HostSyncCounts& into_;
  HostSyncCounts start_;
};

}  // namespace ts::gpu
