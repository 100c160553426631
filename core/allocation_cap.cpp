#include "core/allocation_cap.h"

#include <cstdlib>
#include <new>

namespace {

thread_local std::size_t t_cap = 0;  // bytes; 0: no cap

void* allocate(std::size_t bytes) {
  if (t_cap != 0 && bytes > t_cap) throw std::bad_alloc();
  for (;;) {
    if (void* p = std::malloc(bytes != 0 ? bytes : 1)) return p;
    // The standard's contract: call the new-handler until it frees memory or gives up.
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

}  // namespace

namespace ts {

AllocationCap::AllocationCap(std::size_t max_bytes) : previous_(t_cap) { t_cap = max_bytes; }
AllocationCap::~AllocationCap() { t_cap = previous_; }

}  // namespace ts

// The replaceable global allocation functions (the unaligned ones; the default operator delete frees
// with free(), which matches malloc, and the nothrow forms call these).
void* operator new(std::size_t bytes) { return allocate(bytes); }
void* operator new[](std::size_t bytes) { return allocate(bytes); }
