#include "mcslam/core/alloc_counter.hpp"

#include <atomic>

namespace mcslam::alloc {
namespace detail {
// Set by alloc_hooks.cpp when the replacement operator new is linked in.
std::atomic<bool> g_hooks_linked{false};
thread_local uint64_t t_count = 0;
std::atomic<uint64_t> g_total{0};
}  // namespace detail

bool available() { return detail::g_hooks_linked.load(std::memory_order_relaxed); }
uint64_t threadCount() { return detail::t_count; }
uint64_t totalCount() { return detail::g_total.load(std::memory_order_relaxed); }
void noteAllocation() {
  ++detail::t_count;
  detail::g_total.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace mcslam::alloc
