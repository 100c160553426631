#include "gpu/host_sync.h"

#include <fmt/format.h>

namespace ts::gpu {

namespace {
thread_local HostSyncCounts counts;
}  // namespace

HostSyncCounts& HostSyncCounts::operator+=(const HostSyncCounts& other) {
  reads += other.reads;
  finishes += other.finishes;
  fence_waits += other.fence_waits;
  query_reads += other.query_reads;
  return *this;
}

HostSyncCounts operator-(HostSyncCounts a, const HostSyncCounts& b) {
  a.reads -= b.reads;
  a.finishes -= b.finishes;
  a.fence_waits -= b.fence_waits;
  a.query_reads -= b.query_reads;
  return a;
}

HostSyncCounts host_sync_counts() { return counts; }

void count_read() { ++counts.reads; }
void count_finish() { ++counts.finishes; }
void count_fence_wait() { ++counts.fence_waits; }
void count_query_read() { ++counts.query_reads; }

std::string host_sync_report(const std::vector<HostSyncPhase>& phases) {
  std::string out = fmt::format("{:<52} {:>8} {:>8} {:>8} {:>8} {:>8}  {}\n", "host-GPU round trips", "total",
                                "reads", "finishes", "fences", "queries", "per unit");
  for (const HostSyncPhase& p : phases) {
    const HostSyncCounts& c = p.counts;
    const std::string name = p.units > 0 ? fmt::format("{} ({})", p.name, p.units) : p.name;
    const std::string per =
        p.units > 0 ? fmt::format("{:.3g} per {}",
                                  static_cast<double>(c.total()) / static_cast<double>(p.units), p.unit)
                    : "";
    out += fmt::format("{:<52} {:>8} {:>8} {:>8} {:>8} {:>8}  {}\n", name, c.total(), c.reads, c.finishes,
                       c.fence_waits, c.query_reads, per);
  }
  return out;
}

}  // namespace ts::gpu
