// Counts every heap allocation of the process, per thread and in total, by interposing the C
// allocator (glibc exports __libc_* for exactly this) and routing operator new through it. This
// catches C++ containers, Eigen (which calls malloc directly), OpenCV and CHOLMOD alike.
// Linked only where counting is wanted (tests, benchmarks, the daemon); the core never needs it.
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <new>

#include "mcslam/core/alloc_counter.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace mcslam::alloc::detail {
extern std::atomic<bool> g_hooks_linked;
namespace {
struct MarkLinked {
  MarkLinked() { g_hooks_linked.store(true); }
} mark_linked;
}  // namespace
}  // namespace mcslam::alloc::detail

extern "C" {
void* malloc(std::size_t n) {
  mcslam::alloc::noteAllocation();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  mcslam::alloc::noteAllocation();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  mcslam::alloc::noteAllocation();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
void* memalign(std::size_t align, std::size_t n) {
  mcslam::alloc::noteAllocation();
  return __libc_memalign(align, n);
}
void* aligned_alloc(std::size_t align, std::size_t n) { return memalign(align, n); }
int posix_memalign(void** out, std::size_t align, std::size_t n) {
  void* p = memalign(align, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
}

namespace {
void* newImpl(std::size_t n, std::size_t align) {
  if (n == 0) n = 1;
  void* p = align <= alignof(std::max_align_t) ? malloc(n) : memalign(align, n);
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t n) { return newImpl(n, 0); }
void* operator new[](std::size_t n) { return newImpl(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) { return newImpl(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return newImpl(n, static_cast<std::size_t>(a)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return malloc(n ? n : 1); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return malloc(n ? n : 1); }
void operator delete(void* p) noexcept { free(p); }
void operator delete[](void* p) noexcept { free(p); }
void operator delete(void* p, std::size_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t) noexcept { free(p); }
void operator delete(void* p, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { free(p); }
