#pragma once
// Wall time of a stage, for the --timings tables and the stage seconds of --json. Host time only:
// GPU kernels are timed by gpu::Queue's timer queries, which are read once at the end.
#include <chrono>

namespace ts {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Runs `work` and adds its wall time to `total` [s].
template <class Work>
void timed(double& total, Work&& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  total += seconds_since(start);
}

}  // namespace ts
