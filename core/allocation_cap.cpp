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

// The replaceable global allocation functions, every unaligned form, so that what these allocate with
// malloc is always freed with free (a sanitizer's own operator delete would report the mismatch). The
// aligned forms stay the library's, paired with each other.
void* operator new(std::size_t bytes) { return allocate(bytes); }
void* operator new[](std::size_t bytes) { return allocate(bytes); }
void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept {
  try {
    return allocate(bytes);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t bytes, const std::nothrow_t& tag) noexcept { return operator new(bytes, tag); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
