#pragma once
// A cap on the size of any single allocation the calling thread makes through operator new while a
// scope lasts: above it, operator new throws std::bad_alloc at once instead of reserving the memory.
//
// Why: third-party readers trust length fields. OpenVDB's reader, given a 64 kB .vdb whose transform
// type name claims 4 GiB, reserved and zero-filled it (and more): 43 s and 5.9 GB of memory before it
// failed (tests/sdf/bad_vdb/, found by fuzz_vdb). No single allocation of a legitimate read comes near
// the file's own size, so a cap of a few times that turns the hostile file into an immediate, clear error.
//
// The cap is per thread (thread_local) and nests (the innermost scope rules while it lasts). It
// replaces the global operator new and operator new[] of every program that links this file; with no
// cap in force they are malloc plus the standard's bad_alloc, so nothing else changes.
#include <cstddef>

namespace ts {

class AllocationCap {
 public:
  explicit AllocationCap(std::size_t max_bytes);
  ~AllocationCap();
  AllocationCap(const AllocationCap&) = delete;
  AllocationCap& operator=(const AllocationCap&) = delete;

 private:
  std::size_t previous_;
};

}  // namespace ts
