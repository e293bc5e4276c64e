#include "cholmod_arena.hpp"

#include <SuiteSparse_config.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace mcslam::backend {

// First-fit allocator over an implicit list of blocks in address order. CHOLMOD makes a few
// dozen allocations per analysis and a handful per factorization, so a linear walk is cheap;
// adjacent free blocks are merged during the walk.
struct CholmodArena::Header {
  size_t size;  // whole block, header included, multiple of kAlign
  size_t free;
};

namespace {
constexpr size_t kAlign = 16;
constexpr size_t kHeader = 16;
static_assert(sizeof(CholmodArena::Header*) <= kHeader);
size_t roundUp(size_t n) { return (n + kAlign - 1) & ~(kAlign - 1); }

// Registry of live arenas, so a free finds its owner whichever arena is active.
constexpr int kMaxArenas = 64;
std::array<std::atomic<CholmodArena*>, kMaxArenas> g_arenas{};
thread_local CholmodArena* t_active = nullptr;

CholmodArena* ownerOf(const void* p) {
  for (auto& slot : g_arenas) {
    CholmodArena* a = slot.load(std::memory_order_acquire);
    if (a && a->owns(p)) return a;
  }
  return nullptr;
}

void* hookMalloc(size_t n) {
  if (CholmodArena* a = t_active) {
    if (void* p = a->allocate(n)) return p;
    a->noteOverflow();
  }
  return std::malloc(n);
}
void* hookCalloc(size_t n, size_t size) {
  if (CholmodArena* a = t_active) {
    if (void* p = a->allocate(n * size)) {
      std::memset(p, 0, n * size);
      return p;
    }
    a->noteOverflow();
  }
  return std::calloc(n, size);
}
void* hookRealloc(void* p, size_t n) {
  if (!p) return hookMalloc(n);
  if (CholmodArena* a = ownerOf(p)) {
    if (void* q = a->reallocate(p, n)) return q;
    a->noteOverflow();
    // Move the block out to the heap; the old arena block is released.
    void* q = std::malloc(n);
    if (q) {
      std::memcpy(q, p, std::min(n, a->payloadBytes(p)));
      a->release(p);
    }
    return q;
  }
  return std::realloc(p, n);
}
void hookFree(void* p) {
  if (!p) return;
  if (CholmodArena* a = ownerOf(p)) {
    a->release(p);
    return;
  }
  std::free(p);
}

void installHooksOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    SuiteSparse_config.malloc_func = hookMalloc;
    SuiteSparse_config.calloc_func = hookCalloc;
    SuiteSparse_config.realloc_func = hookRealloc;
    SuiteSparse_config.free_func = hookFree;
  });
}
}  // namespace

CholmodArena::CholmodArena(size_t bytes) {
  bytes = std::max(roundUp(bytes), 4 * kAlign);
  storage_.resize(bytes / sizeof(std::max_align_t) + 1);
  begin_ = reinterpret_cast<char*>(storage_.data());
  end_ = begin_ + bytes;
  Header* h = first();
  h->size = bytes;
  h->free = 1;
  installHooksOnce();
  for (auto& slot : g_arenas) {
    CholmodArena* expected = nullptr;
    if (slot.compare_exchange_strong(expected, this)) return;
  }
  std::abort();  // more live solvers than the registry holds: a programming error
}

CholmodArena::~CholmodArena() {
  for (auto& slot : g_arenas) {
    CholmodArena* expected = this;
    slot.compare_exchange_strong(expected, nullptr);
  }
}

CholmodArena::Header* CholmodArena::first() const { return reinterpret_cast<Header*>(begin_); }
CholmodArena::Header* CholmodArena::next(Header* h) const {
  char* n = reinterpret_cast<char*>(h) + h->size;
  return n < end_ ? reinterpret_cast<Header*>(n) : nullptr;
}

void* CholmodArena::allocate(size_t bytes) {
  const size_t need = roundUp(std::max<size_t>(bytes, 1)) + kHeader;
  for (Header* h = first(); h; h = next(h)) {
    if (!h->free) continue;
    for (Header* n = next(h); n && n->free; n = next(h)) h->size += n->size;  // merge free neighbours
    if (h->size < need) continue;
    if (h->size - need >= kHeader + kAlign) {  // split off the rest
      Header* rest = reinterpret_cast<Header*>(reinterpret_cast<char*>(h) + need);
      rest->size = h->size - need;
      rest->free = 1;
      h->size = need;
    }
    h->free = 0;
    in_use_ += h->size;
    peak_ = std::max(peak_, in_use_);
    return reinterpret_cast<char*>(h) + kHeader;
  }
  return nullptr;
}

void CholmodArena::release(void* p) {
  Header* h = reinterpret_cast<Header*>(static_cast<char*>(p) - kHeader);
  h->free = 1;
  in_use_ -= h->size;
}

size_t CholmodArena::payloadBytes(const void* p) const {
  const Header* h = reinterpret_cast<const Header*>(static_cast<const char*>(p) - kHeader);
  return h->size - kHeader;
}

void* CholmodArena::reallocate(void* p, size_t bytes) {
  const size_t payload = payloadBytes(p);
  if (bytes <= payload) return p;
  void* q = allocate(bytes);
  if (!q) return nullptr;
  std::memcpy(q, p, payload);
  release(p);
  return q;
}

ArenaScope::ArenaScope(CholmodArena& arena) : previous_(t_active) { t_active = &arena; }
ArenaScope::~ArenaScope() { t_active = previous_; }

}  // namespace mcslam::backend
