#include "daemon/assembly_stage.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "realtime/scheduling.hpp"

namespace mcslam::platform {

AssemblyStage::AssemblyStage(const std::vector<std::pair<int, int>>& sizes, const AssemblySettings& settings,
                             CameraRings& in, RigRing& out, const WarmUp& warm_up)
    : settings_(settings),
      in_(in),
      out_(out),
      warm_up_(warm_up),
      assembler_(sizes, settings.pending_rig_frames, settings.match_by, settings.tolerance_ns, settings.timeout_ns) {}

void AssemblyStage::start() {
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void AssemblyStage::stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  in_.bell().ring();
  thread_.join();
}

bool AssemblyStage::emit(int64_t now, bool force) {
  RigFrame& out = out_.slot();
  if (!assembler_.next(out, now, force)) return false;
  if (out_.publish()) rig_drops_.fetch_add(1, std::memory_order_relaxed);
  rig_frames_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

void AssemblyStage::run() {
  nameThisThread("mcslam-assemble");
  if (const auto why = setRealtimePriority(settings_.priority); !why.empty()) spdlog::warn("assembly thread: {}", why);
  const int64_t poll = std::min<int64_t>(10000000, settings_.timeout_ns / 2 + 1);
  while (!stop_.load(std::memory_order_relaxed)) {
    const uint32_t ticket = in_.bell().ticket();
    bool any = false;
    for (int c = 0; c < in_.cameras(); ++c) {
      auto& ring = in_.ring(c);
      while (CameraFrame* f = ring.acquire()) {
        while (!assembler_.add(c, *f, monotonicNowNs())) emit(monotonicNowNs(), true);
        ring.release();
        any = true;
      }
    }
    while (emit(monotonicNowNs(), false)) {
    }
    meter_.note(warm_up_.warm());
    if (!any) in_.bell().wait(ticket, poll);
  }
  while (emit(monotonicNowNs(), true)) {  // what was captured still goes out
  }
}

}  // namespace mcslam::platform
