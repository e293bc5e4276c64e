#pragma once
// Groups camera images into rig frames, by trigger index or by capture time within a tolerance.
// Up to `pending` rig frames are assembled at once; they leave in order: a frame leaves when it is
// complete and every older one has left, or when it has waited longer than the timeout (then without
// the missing cameras), or when its place is needed for a newer frame. Fixed memory; single thread.
#include <atomic>
#include <cstdint>
#include <vector>

#include "daemon/frames.hpp"
#include "sources/camera_frame.hpp"

namespace mcslam::platform {

class RigAssembler {
 public:
  enum class MatchBy { TriggerCount, Timestamp };

  // sizes: image size per camera.
  RigAssembler(const std::vector<std::pair<int, int>>& sizes, uint32_t pending, MatchBy match_by, int64_t tolerance_ns,
               int64_t timeout_ns);

  // Takes camera `cam`'s frame (its image buffer is swapped with a spare of the same size, so the
  // caller's slot stays usable). `now_mono_ns` drives the timeout. Returns false, taking nothing, when
  // the frame needs a new place and all are taken: call next(..., force=true) and add it again.
  bool add(int cam, CameraFrame& frame, int64_t now_mono_ns);

  // Moves the oldest rig frame into `out` (buffers swapped) if it may leave: complete, timed out, or
  // forced. False when none may leave yet.
  bool next(RigFrame& out, int64_t now_mono_ns, bool force = false);

  // Counters, readable from any thread.
  uint64_t partialFrames() const { return partial_.load(std::memory_order_relaxed); }  // left with a camera missing
  uint64_t lateImages() const { return late_.load(std::memory_order_relaxed); }        // came after their frame left
  uint64_t duplicateImages() const { return duplicate_.load(std::memory_order_relaxed); }
  uint32_t pendingFrames() const { return pending_count_.load(std::memory_order_relaxed); }
  int cameras() const { return cameras_; }

 private:
  struct Pending {
    RigFrame frame;
    bool used = false;
    int64_t first_arrival_ns = 0;
    uint64_t order = 0;  // creation order
  };
  Pending* find(const CameraFrame& f);
  Pending* oldest();
  bool matches(const Pending& p, const CameraFrame& f) const;

  int cameras_;
  MatchBy match_by_;
  int64_t tolerance_ns_, timeout_ns_;
  std::vector<Pending> pending_;
  uint64_t next_order_ = 0;
  bool any_emitted_ = false;
  uint64_t last_emitted_index_ = 0;
  Timestamp last_emitted_t_ = 0;
  std::atomic<uint64_t> partial_{0}, late_{0}, duplicate_{0};
  std::atomic<uint32_t> pending_count_{0};
};

}  // namespace mcslam::platform
