// StageRunner, with a processor that records the order of its calls: frames are prepared and finished in
// capture order, the caller's tags travel with them, prepare() waits for a free slot (never overwrites a
// prepared frame), close() ends the finishing side, and a processor without stages runs whole.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "mcslam/pipeline/stage_runner.hpp"

using namespace mcslam;

namespace {

// Two stages; the pose of a frame is made from what its slot held, so a slot overwritten before it was finished
// gives a wrong pose.
class RecordingStages : public FrameProcessor {
 public:
  explicit RecordingStages(int slots) : slot_sequence_(static_cast<std::size_t>(slots), ~0ull) {}
  void process(const RigFrameView&, PoseEstimate&) override { ADD_FAILURE() << "process() on a staged processor"; }
  int stageSlots() const override { return static_cast<int>(slot_sequence_.size()); }
  void prepare(const RigFrameView& frame, int slot) override {
    std::lock_guard<std::mutex> lock(mutex_);
    EXPECT_EQ(slot_sequence_[static_cast<std::size_t>(slot)], ~0ull) << "slot " << slot << " overwritten";
    slot_sequence_[static_cast<std::size_t>(slot)] = frame.sequence;
    calls_.push_back(call('p', frame.sequence));
  }
  void finish(int slot, PoseEstimate& out) override {
    std::lock_guard<std::mutex> lock(mutex_);
    out = PoseEstimate{};
    out.sequence = slot_sequence_[static_cast<std::size_t>(slot)];
    slot_sequence_[static_cast<std::size_t>(slot)] = ~0ull;
    calls_.push_back(call('f', out.sequence));
  }
  std::vector<std::string> calls() {
    std::lock_guard<std::mutex> lock(mutex_);
    return calls_;
  }

 private:
  static std::string call(char stage, uint64_t sequence) {
    std::string s = std::to_string(sequence);
    s.insert(s.begin(), stage);
    return s;
  }
  std::mutex mutex_;
  std::vector<uint64_t> slot_sequence_;
  std::vector<std::string> calls_;
};

class WholeFrames : public FrameProcessor {
 public:
  void process(const RigFrameView& frame, PoseEstimate& out) override {
    out = PoseEstimate{};
    out.sequence = frame.sequence;
    out.t = frame.t;
    ++processed;
  }
  int processed = 0;
};

RigFrameView frame(uint64_t sequence) {
  RigFrameView v;
  v.sequence = sequence;
  v.t = static_cast<Timestamp>(1000 + sequence);
  return v;
}

}  // namespace

TEST(StageRunner, OneThreadPreparesAndFinishesEachFrameInTurn) {
  RecordingStages stages(2);
  StageRunner<int> runner(stages);
  ASSERT_TRUE(runner.canOverlap());
  for (uint64_t i = 0; i < 5; ++i) {
    runner.prepare(frame(i), static_cast<int>(10 * i));
    PoseEstimate pose;
    int tag = -1;
    ASSERT_TRUE(runner.finish(pose, tag));
    EXPECT_EQ(pose.sequence, i);
    EXPECT_EQ(tag, static_cast<int>(10 * i));
  }
  EXPECT_EQ(runner.waiting(), 0u);
  const std::vector<std::string> expected{"p0", "f0", "p1", "f1", "p2", "f2", "p3", "f3", "p4", "f4"};
  EXPECT_EQ(stages.calls(), expected);
}

TEST(StageRunner, TwoThreadsKeepTheOrderAndTheTagsAndNeverOverwriteAWaitingFrame) {
  constexpr int kFrames = 2000;
  RecordingStages stages(2);
  StageRunner<std::string> runner(stages);
  std::thread producer([&] {
    for (uint64_t i = 0; i < kFrames; ++i) runner.prepare(frame(i), "frame " + std::to_string(i));
    runner.close();
  });
  PoseEstimate pose;
  std::string tag;
  uint64_t n = 0;
  while (runner.finish(pose, tag)) {
    EXPECT_EQ(pose.sequence, n);
    EXPECT_EQ(tag, "frame " + std::to_string(n));
    ++n;
  }
  producer.join();
  EXPECT_EQ(n, static_cast<uint64_t>(kFrames));
  // Frame i + 2 is never prepared before frame i is finished (two slots).
  const std::vector<std::string> calls = stages.calls();
  std::vector<std::size_t> at(2 * kFrames);
  for (std::size_t k = 0; k < calls.size(); ++k) {
    const std::size_t i = std::stoul(calls[k].substr(1));
    at[2 * i + (calls[k][0] == 'f' ? 1 : 0)] = k;
  }
  for (std::size_t i = 0; i + 2 < kFrames; ++i) EXPECT_LT(at[2 * i + 1], at[2 * (i + 2)]) << "frame " << i;
}

TEST(StageRunner, PrepareWaitsForAFreeSlot) {
  RecordingStages stages(2);
  StageRunner<> runner(stages);
  runner.prepare(frame(0));
  runner.prepare(frame(1));
  std::atomic<bool> third_prepared{false};
  std::thread producer([&] {
    runner.prepare(frame(2));
    third_prepared = true;
  });
  // Liveness only: the producer cannot get past prepare() until a frame is finished.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(third_prepared.load());
  PoseEstimate pose;
  ASSERT_TRUE(runner.finish(pose));
  EXPECT_EQ(pose.sequence, 0u);
  producer.join();
  EXPECT_TRUE(third_prepared.load());
  EXPECT_EQ(runner.waiting(), 2u);
}

TEST(StageRunner, CloseEndsTheFinishingSideOnceEveryPreparedFrameIsFinished) {
  RecordingStages stages(2);
  StageRunner<> runner(stages);
  runner.prepare(frame(7));
  runner.close();
  PoseEstimate pose;
  ASSERT_TRUE(runner.finish(pose));
  EXPECT_EQ(pose.sequence, 7u);
  pose.sequence = 99;
  EXPECT_FALSE(runner.finish(pose));
  EXPECT_EQ(pose.sequence, 99u);  // untouched
}

TEST(StageRunner, AProcessorWithoutStagesRunsWholeInPrepare) {
  WholeFrames whole;
  StageRunner<int> runner(whole);
  EXPECT_FALSE(runner.canOverlap());
  EXPECT_EQ(runner.slots(), 1);
  runner.prepare(frame(3), 33);
  EXPECT_EQ(whole.processed, 1);
  PoseEstimate pose;
  int tag = 0;
  ASSERT_TRUE(runner.finish(pose, tag));
  EXPECT_EQ(pose.sequence, 3u);
  EXPECT_EQ(pose.t, 1003);
  EXPECT_EQ(tag, 33);
}
