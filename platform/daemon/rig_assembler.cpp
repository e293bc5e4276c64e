#include "daemon/rig_assembler.hpp"

#include <utility>

namespace mcslam::platform {

RigAssembler::RigAssembler(const std::vector<std::pair<int, int>>& sizes, uint32_t pending, MatchBy match_by,
                           int64_t tolerance_ns, int64_t timeout_ns)
    : cameras_(static_cast<int>(sizes.size())),
      match_by_(match_by),
      tolerance_ns_(tolerance_ns),
      timeout_ns_(timeout_ns),
      pending_(pending) {
  for (auto& p : pending_) p.frame.allocate(sizes);
}

bool RigAssembler::matches(const Pending& p, const CameraFrame& f) const {
  if (match_by_ == MatchBy::TriggerCount) return p.frame.sequence == f.trigger_index;
  const int64_t d = f.capture_ns - p.frame.capture_ns;
  return d <= tolerance_ns_ && d >= -tolerance_ns_;
}

RigAssembler::Pending* RigAssembler::find(const CameraFrame& f) {
  for (auto& p : pending_)
    if (p.used && matches(p, f)) return &p;
  return nullptr;
}

// The pending frame that must leave first: the smallest trigger index, or the earliest time.
RigAssembler::Pending* RigAssembler::oldest() {
  Pending* best = nullptr;
  for (auto& p : pending_) {
    if (!p.used) continue;
    const bool older = !best || (match_by_ == MatchBy::TriggerCount ? p.frame.sequence < best->frame.sequence
                                                                    : p.frame.capture_ns < best->frame.capture_ns);
    if (older) best = &p;
  }
  return best;
}

bool RigAssembler::add(int cam, CameraFrame& f, int64_t now_mono_ns) {
  if (cam < 0 || cam >= cameras_) return true;
  if (any_emitted_) {
    const bool late = match_by_ == MatchBy::TriggerCount ? f.trigger_index <= last_emitted_index_
                                                         : f.capture_ns <= last_emitted_t_ + tolerance_ns_;
    if (late) {
      late_.fetch_add(1, std::memory_order_relaxed);
      return true;
    }
  }
  Pending* p = find(f);
  if (!p) {
    for (auto& q : pending_)
      if (!q.used) {
        p = &q;
        break;
      }
    if (!p) return false;  // every place taken: the caller lets the oldest leave first
    p->used = true;
    pending_count_.fetch_add(1, std::memory_order_relaxed);
    p->first_arrival_ns = now_mono_ns;
    p->order = next_order_++;
    p->frame.sequence = f.trigger_index;
    p->frame.capture_ns = f.capture_ns;  // the key for timestamp matching
    p->frame.trigger_mono_ns = f.trigger_mono_ns;
    for (int c = 0; c < cameras_; ++c) p->frame.present[c] = false;
  }
  if (p->frame.present[cam]) {
    duplicate_.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
  std::swap(p->frame.images[cam], f.image);
  p->frame.present[cam] = true;
  return true;
}

bool RigAssembler::next(RigFrame& out, int64_t now_mono_ns, bool force) {
  Pending* p = oldest();
  if (!p) return false;
  const int present = p->frame.presentCount();
  const bool complete = present == cameras_;
  const bool timed_out = now_mono_ns - p->first_arrival_ns >= timeout_ns_;
  if (!complete && !timed_out && !force) return false;
  for (int c = 0; c < cameras_; ++c) {
    std::swap(out.images[c], p->frame.images[c]);
    out.present[c] = p->frame.present[c];
  }
  out.capture_ns = p->frame.capture_ns;
  out.sequence = p->frame.sequence;
  out.trigger_mono_ns = p->frame.trigger_mono_ns;
  if (!complete) partial_.fetch_add(1, std::memory_order_relaxed);
  any_emitted_ = true;
  last_emitted_index_ = p->frame.sequence;
  last_emitted_t_ = p->frame.capture_ns;
  p->used = false;
  pending_count_.fetch_sub(1, std::memory_order_relaxed);
  return true;
}

}  // namespace mcslam::platform
