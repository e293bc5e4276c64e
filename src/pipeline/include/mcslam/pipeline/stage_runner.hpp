#pragma once
// The one way to run a FrameProcessor frame by frame, used by mcslam-run and mcslamd: frames are prepared
// (FrameProcessor::prepare, the part that reads the images) in capture order into the processor's slots and
// finished (FrameProcessor::finish) in the same order. The caller chooses the threads: with overlap, one thread
// prepares while another finishes (the front-end of the next frame while this one is tracked); without, one
// thread calls prepare() then finish() for each frame. A processor without stages is run whole (process()) in
// prepare(), its pose kept for finish(). The poses are those of process() either way.
//
// A prepared frame waits in its slot; prepare() waits for a free slot, finish() for a prepared frame (futex
// waits on atomics: no lock, no allocation after construction). Each frame carries a `Tag` of the caller's
// (what it needs to know again when the frame is finished: trigger time, an error message), copied into the
// slot before the frame is handed to the finishing side.
#include <atomic>
#include <cstdint>
#include <vector>

#include "mcslam/pipeline/frame_processor.hpp"

namespace mcslam {

// The slot handling, independent of the caller's tag.
class StageSlots {
 public:
  explicit StageSlots(FrameProcessor& processor);
  StageSlots(const StageSlots&) = delete;
  StageSlots& operator=(const StageSlots&) = delete;

  // The processor has stages: prepare() and finish() may run on two threads at once.
  bool canOverlap() const { return staged_; }
  int slots() const { return static_cast<int>(poses_.size()); }
  // Frames prepared and not yet finished (either thread; approximate while they run).
  uint64_t waiting() const {
    return prepared_.load(std::memory_order_acquire) - finished_.load(std::memory_order_acquire);
  }

  // Preparing thread: no frame will follow; the finishing side ends once the prepared ones are finished.
  void close();

 protected:
  int reserve();                                      // preparing thread: waits for a free slot
  void prepare(int slot, const RigFrameView& frame);  // prepares into it and hands it over
  int next();                                         // finishing thread: waits; -1 when closed and all finished
  void finish(int slot, PoseEstimate& out);           // finishes it; the slot is free again

 private:
  void signal();
  FrameProcessor& processor_;
  bool staged_;
  std::vector<PoseEstimate> poses_;  // a processor without stages: the pose process() gave, per slot
  alignas(64) std::atomic<uint64_t> prepared_{0};
  alignas(64) std::atomic<uint64_t> finished_{0};
  std::atomic<bool> closed_{false};
  alignas(64) std::atomic<uint32_t> changes_{0};  // what both sides wait on: any of the above changed
};

struct NoStageTag {};

template <typename Tag = NoStageTag>
class StageRunner : public StageSlots {
 public:
  explicit StageRunner(FrameProcessor& processor) : StageSlots(processor), tags_(static_cast<std::size_t>(slots())) {}

  // Preparing thread: waits until the frame slots() before this one is finished, then prepares this one. The
  // frame's images may be reused when it returns.
  void prepare(const RigFrameView& frame, const Tag& tag = Tag{}) {
    const int slot = reserve();
    tags_[static_cast<std::size_t>(slot)] = tag;
    StageSlots::prepare(slot, frame);
  }
  // Finishing thread: waits for the next prepared frame and finishes it into `out`, its tag into `tag`. False,
  // touching neither, once close() was called and every prepared frame is finished.
  bool finish(PoseEstimate& out, Tag& tag) {
    const int slot = next();
    if (slot < 0) return false;
    tag = tags_[static_cast<std::size_t>(slot)];
    StageSlots::finish(slot, out);
    return true;
  }
  bool finish(PoseEstimate& out) {
    Tag tag;
    return finish(out, tag);
  }

 private:
  std::vector<Tag> tags_;
};

}  // namespace mcslam
