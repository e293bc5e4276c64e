#pragma once
// The simulator's threads: the shared WorkerPool, driven with forEach() so that the calling thread works too.
#include <algorithm>

#include "mcslam/core/worker_pool.hpp"

namespace mcslam::sim {

// Workers for `threads` threads in all, the calling thread one of them (threads <= 0: one per hardware thread).
inline int poolWorkers(int threads) { return std::max(1, threads > 0 ? threads : WorkerPool::hardwareThreads()) - 1; }

}  // namespace mcslam::sim
