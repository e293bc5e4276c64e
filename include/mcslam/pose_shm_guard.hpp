#pragma once
// Survives the truncation of a mapped pose segment. Touching a page of a shared-memory mapping beyond the
// file's end raises SIGBUS, and the owner of the segment (or root) can truncate it at any time. With the guard
// installed, a SIGBUS inside a registered mapping replaces that mapping with private zero pages, marks it lost
// and lets the access complete; any other SIGBUS goes to the previous disposition (by default the process
// ends, as without the guard). libwayland-server protects its wl_shm pools the same way.
//
// Process-wide and fixed-size: up to kMaxGuardedMappings mappings; a mapping beyond that is not guarded.
#include <signal.h>
#include <sys/mman.h>

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace mcslam::pose::shm_guard {

inline constexpr int kMaxGuardedMappings = 16;

struct Entry {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 guarded
  std::atomic<uintptr_t> base{0};
  std::atomic<std::size_t> size{0};
  std::atomic<int> prot{0};
  std::atomic<bool> lost{false};
};

inline Entry g_entries[kMaxGuardedMappings];
inline std::atomic<bool> g_installed{false};
inline struct sigaction g_previous {};

inline void onSigbus(int sig, siginfo_t* info, void* context) {
  const auto address = reinterpret_cast<uintptr_t>(info->si_addr);
  for (Entry& e : g_entries) {
    if (e.state.load(std::memory_order_acquire) != 2) continue;
    const uintptr_t base = e.base.load(std::memory_order_relaxed);
    if (address < base || address - base >= e.size.load(std::memory_order_relaxed)) continue;
    // mmap is a plain system call here; the fault is synchronous, in the thread that touched the mapping.
    void* p = ::mmap(reinterpret_cast<void*>(base), e.size.load(std::memory_order_relaxed),
                     e.prot.load(std::memory_order_relaxed), MAP_FIXED | MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) break;
    e.lost.store(true, std::memory_order_release);
    return;  // the access is retried, now on zero pages
  }
  if ((g_previous.sa_flags & SA_SIGINFO) && g_previous.sa_sigaction) {
    g_previous.sa_sigaction(sig, info, context);
    return;
  }
  if (g_previous.sa_handler != SIG_DFL && g_previous.sa_handler != SIG_IGN) {
    g_previous.sa_handler(sig);
    return;
  }
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  ::sigaction(sig, &dfl, nullptr);
  // A fault recurs when the access is retried; a SIGBUS sent by kill() must be raised again.
  if (info->si_code <= 0) ::raise(sig);
}

// Installs the handler once per process. False when sigaction fails.
inline bool install() {
  if (g_installed.exchange(true)) return true;
  struct sigaction sa {};
  sa.sa_sigaction = onSigbus;
  sa.sa_flags = SA_SIGINFO | SA_ONSTACK;
  sigemptyset(&sa.sa_mask);
  if (::sigaction(SIGBUS, &sa, &g_previous) == 0) return true;
  g_installed.store(false);
  return false;
}

inline bool installed() { return g_installed.load(std::memory_order_acquire); }

// Registers a mapping; returns its index, or -1 when all entries are taken (then it is not guarded).
inline int add(const void* base, std::size_t size, int prot) {
  for (int i = 0; i < kMaxGuardedMappings; ++i) {
    Entry& e = g_entries[i];
    int expected = 0;
    if (!e.state.compare_exchange_strong(expected, 1, std::memory_order_acquire)) continue;
    e.base.store(reinterpret_cast<uintptr_t>(base), std::memory_order_relaxed);
    e.size.store(size, std::memory_order_relaxed);
    e.prot.store(prot, std::memory_order_relaxed);
    e.lost.store(false, std::memory_order_relaxed);
    e.state.store(2, std::memory_order_release);
    return i;
  }
  return -1;
}

// Before the mapping is unmapped.
inline void remove(int index) {
  if (index >= 0 && index < kMaxGuardedMappings) g_entries[index].state.store(0, std::memory_order_release);
}

// True once a SIGBUS replaced the mapping: its contents are zeros now, and it no longer shares the segment.
inline bool lost(int index) {
  return index >= 0 && index < kMaxGuardedMappings && g_entries[index].lost.load(std::memory_order_acquire);
}

}  // namespace mcslam::pose::shm_guard
