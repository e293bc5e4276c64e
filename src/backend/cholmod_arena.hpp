#pragma once
// A fixed buffer that serves CHOLMOD's allocations, so that analysis and factorization allocate
// nothing from the heap after construction.
//
// SuiteSparse 5 routes every CHOLMOD allocation through the global SuiteSparse_config function
// pointers. We point them (once per process) at hooks that use the arena made active on the
// calling thread by an ArenaScope, and fall back to malloc otherwise, so other CHOLMOD users in
// the same process (Ceres in tests) are unaffected. Frees find the owning arena by address.
#include <cstddef>
#include <vector>

namespace mcslam::backend {

class CholmodArena {
 public:
  explicit CholmodArena(size_t bytes);
  ~CholmodArena();
  CholmodArena(const CholmodArena&) = delete;
  CholmodArena& operator=(const CholmodArena&) = delete;

  // nullptr when the request does not fit (the hook then falls back to malloc, counted).
  void* allocate(size_t bytes);
  void release(void* p);
  void* reallocate(void* p, size_t bytes);
  bool owns(const void* p) const { return p >= begin_ && p < end_; }
  size_t payloadBytes(const void* p) const;

  size_t capacity() const { return static_cast<size_t>(end_ - begin_); }
  size_t bytesInUse() const { return in_use_; }
  size_t peakBytes() const { return peak_; }
  size_t overflows() const { return overflows_; }
  void noteOverflow() { ++overflows_; }

  struct Header;  // of each block, public only for the allocator's helpers

 private:
  Header* first() const;
  Header* next(Header* h) const;

  std::vector<std::max_align_t> storage_;
  char* begin_ = nullptr;
  char* end_ = nullptr;
  size_t in_use_ = 0, peak_ = 0, overflows_ = 0;
};

// Makes `arena` serve CHOLMOD's allocations on this thread for the scope's lifetime.
class ArenaScope {
 public:
  explicit ArenaScope(CholmodArena& arena);
  ~ArenaScope();
  ArenaScope(const ArenaScope&) = delete;
  ArenaScope& operator=(const ArenaScope&) = delete;

 private:
  CholmodArena* previous_;
};

}  // namespace mcslam::backend
