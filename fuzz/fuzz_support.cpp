#include "fuzz/fuzz_support.h"

#include <elf.h>
#include <link.h>
#include <sanitizer/asan_interface.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <new>
#include <string>
#include <system_error>

// C++14's sized delete, which <new> declares only under -fsized-deallocation (off in clang 14); the
// runtime (ASan's) defines it, and libraries built with GCC call it.
void operator delete(void* block, std::size_t size) noexcept;

namespace ts::fuzz {
namespace fs = std::filesystem;

namespace {

void remove_scratch() {
  std::error_code ec;
  fs::remove_all(scratch_dir(), ec);
}

// reuse_large_blocks_in: blocks of kLargeBlock bytes or more that the library allocated with operator
// new (each also a block of ASan's, with its redzones) and the one it freed last, kept poisoned.
constexpr std::size_t kLargeBlock = std::size_t{8} << 20;
std::mutex g_large_mutex;
std::uintptr_t g_live[8] = {};  // ~address (hidden from LeakSanitizer: a leaked block stays a leak)
std::size_t g_live_size[8] = {};
void* g_spare = nullptr;
std::size_t g_spare_size = 0;

void* large_new(std::size_t size) {
  if (size < kLargeBlock) return ::operator new(size);
  void* block = nullptr;
  {
    const std::lock_guard lock(g_large_mutex);
    if (g_spare != nullptr && g_spare_size == size) {
      block = g_spare;
      g_spare = nullptr;
      ASAN_UNPOISON_MEMORY_REGION(block, size);
    }
  }
  if (block == nullptr) block = ::operator new(size);
  const std::lock_guard lock(g_large_mutex);
  for (std::size_t i = 0; i < std::size(g_live); ++i) {
    if (g_live[i] == 0) {
      g_live[i] = ~reinterpret_cast<std::uintptr_t>(block);
      g_live_size[i] = size;
      break;
    }
  }  // all taken: the block goes back to ASan when deleted
  return block;
}

// Keeps `block` as the spare if large_new gave it out (and `size`, when known, is its size); true if so.
bool keep_large(void* block, std::size_t size) {
  if (block == nullptr) return false;
  void* old = nullptr;
  std::size_t old_size = 0;
  {
    const std::lock_guard lock(g_large_mutex);
    if (block == g_spare) {  // deleted twice: give it back twice, for ASan to report the double free
      ASAN_UNPOISON_MEMORY_REGION(block, g_spare_size);
      g_spare = nullptr;
      ::operator delete(block);
      return false;
    }
    std::size_t i = 0;
    while (i < std::size(g_live) && g_live[i] != ~reinterpret_cast<std::uintptr_t>(block)) ++i;
    if (i == std::size(g_live) || (size != 0 && size != g_live_size[i])) return false;  // ASan judges it
    g_live[i] = 0;
    old = g_spare;
    old_size = g_spare_size;
    g_spare = block;
    g_spare_size = g_live_size[i];
    ASAN_POISON_MEMORY_REGION(block, g_spare_size);
  }
  if (old != nullptr) {
    ASAN_UNPOISON_MEMORY_REGION(old, old_size);
    ::operator delete(old);
  }
  return true;
}

void large_delete(void* block) noexcept {
  if (!keep_large(block, 0)) ::operator delete(block);
}
void large_sized_delete(void* block, std::size_t size) noexcept {
  if (!keep_large(block, size)) ::operator delete(block, size);
}

// dl_iterate_phdr's callback: points the GOT slots for operator new and delete (scalar, unaligned) of
// the library whose path contains patch.library at the functions above, counting them.
struct Patch {
  const char* library;
  int patched = 0;
};

int patch_library(dl_phdr_info* info, std::size_t, void* data) {
  auto& patch = *static_cast<Patch*>(data);
  if (info->dlpi_name == nullptr || std::strstr(info->dlpi_name, patch.library) == nullptr) return 0;
  const auto base = static_cast<std::uintptr_t>(info->dlpi_addr);
  const ElfW(Dyn)* dynamic = nullptr;
  std::uintptr_t relro_begin = 0, relro_end = 0;
  for (ElfW(Half) i = 0; i < info->dlpi_phnum; ++i) {
    const ElfW(Phdr)& ph = info->dlpi_phdr[i];
    if (ph.p_type == PT_DYNAMIC) dynamic = reinterpret_cast<const ElfW(Dyn)*>(base + ph.p_vaddr);
    if (ph.p_type == PT_GNU_RELRO) relro_begin = base + ph.p_vaddr, relro_end = relro_begin + ph.p_memsz;
  }
  if (dynamic == nullptr) return 1;
  // glibc has already relocated these addresses in place; add the base where it has not.
  const auto address = [base](ElfW(Addr) a) { return a < base ? base + a : static_cast<std::uintptr_t>(a); };
  const ElfW(Sym)* symbols = nullptr;
  const char* names = nullptr;
  const ElfW(Rela)* relocations = nullptr;
  std::size_t relocations_size = 0;
  for (const ElfW(Dyn)* d = dynamic; d->d_tag != DT_NULL; ++d) {
    if (d->d_tag == DT_SYMTAB) symbols = reinterpret_cast<const ElfW(Sym)*>(address(d->d_un.d_ptr));
    if (d->d_tag == DT_STRTAB) names = reinterpret_cast<const char*>(address(d->d_un.d_ptr));
    if (d->d_tag == DT_JMPREL) relocations = reinterpret_cast<const ElfW(Rela)*>(address(d->d_un.d_ptr));
    if (d->d_tag == DT_PLTRELSZ) relocations_size = d->d_un.d_val;
  }
  if (symbols == nullptr || names == nullptr || relocations == nullptr) return 1;
  const long page = ::sysconf(_SC_PAGESIZE);
  for (std::size_t i = 0; i < relocations_size / sizeof(ElfW(Rela)); ++i) {
    const ElfW(Rela)& r = relocations[i];
    if (ELF64_R_TYPE(r.r_info) != R_X86_64_JUMP_SLOT) continue;
    const char* name = names + symbols[ELF64_R_SYM(r.r_info)].st_name;
    void* replacement = std::strcmp(name, "_Znwm") == 0     ? reinterpret_cast<void*>(&large_new)
                        : std::strcmp(name, "_ZdlPv") == 0  ? reinterpret_cast<void*>(&large_delete)
                        : std::strcmp(name, "_ZdlPvm") == 0 ? reinterpret_cast<void*>(&large_sized_delete)
                                                             : nullptr;
    if (replacement == nullptr) continue;
    const std::uintptr_t slot = base + r.r_offset;
    void* slot_page = reinterpret_cast<void*>(slot & ~static_cast<std::uintptr_t>(page - 1));
    if (::mprotect(slot_page, page, PROT_READ | PROT_WRITE) != 0) continue;
    *reinterpret_cast<void**>(slot) = replacement;
    if (slot >= relro_begin && slot < relro_end) ::mprotect(slot_page, page, PROT_READ);
    ++patch.patched;
  }
  return 1;
}

}  // namespace

const fs::path& scratch_dir() {
  // Never destroyed: the atexit handler that removes the folder runs after the destructors of
  // statics constructed before it was registered, this one included.
  static const fs::path& dir = *new fs::path([] {
    // In memory when the system has a tmpfs at /dev/shm: the targets write every input to a file
    // (two for fuzz_body), millions of writes that a disk-backed /tmp need not see.
    std::error_code ec;
    const fs::path base = fs::is_directory("/dev/shm", ec) && ::access("/dev/shm", W_OK) == 0
                              ? fs::path("/dev/shm")
                              : fs::temp_directory_path();
    const fs::path d = base / ("tetrasand-fuzz." + std::to_string(::getpid()));
    fs::create_directories(d);
    std::atexit(remove_scratch);
    return d;
  }());
  return dir;
}

int reuse_large_blocks_in(const char* library) {
  Patch patch{library};
  ::dl_iterate_phdr(patch_library, &patch);
  return patch.patched;
}

fs::path scratch_file(const std::string& name, std::string_view bytes) {
  const fs::path path = scratch_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

}  // namespace ts::fuzz
