#pragma once
// The CPU reference's parallel loops. Each step runs a handful of loops over particles or bodies; on a
// small scene (the 300-grain bed of docs/benchmarks/sim.md) TBB's task set-up and wake-ups cost more
// than the loops' work, so a range shorter than kSerialBelow runs on the calling thread. Every loop
// body writes only its own index's results, so where it runs changes no bit of them.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cstdint>

namespace ts::sim {

// Items a loop needs before it is split over threads: about where TBB's overhead stops dominating
// the per-item work of the contact stage (measured in docs/benchmarks/sim.md, "CPU reference with
// contact lists"). Also the grain TBB splits larger ranges into.
inline constexpr std::uint32_t kSerialBelow = 1024;

// Whether loops run on the calling thread whatever their length: when the arena has one thread (a
// process pinned to one core, or limited by a task_arena), TBB would run every chunk on it anyway,
// after splitting the range and making a task per chunk.
inline bool one_thread() { return tbb::this_task_arena::max_concurrency() == 1; }

// Calls fn(i) for every i in [0, n), in any order and on any thread.
template <typename Fn>
void for_each_index(std::uint32_t n, Fn&& fn) {
  if (n < kSerialBelow || one_thread()) {
    for (std::uint32_t i = 0; i < n; ++i) fn(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, n, kSerialBelow / 4),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      for (std::uint32_t i = r.begin(); i < r.end(); ++i) fn(i);
                    });
}

}  // namespace ts::sim
