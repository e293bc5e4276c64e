#pragma once
// Loop closure over the place map: each new place keyframe looks for an older place it sees again (the database,
// then the relocalizer's verification: generalized P3P, guided search, strict acceptance), among keyframes the
// odometry can no longer reach (of another segment, or `loop_min_keyframes_apart` keyframes older). That detection
// runs on a thread of its own, on copies of the keyframe's features and words, while the map and the database stay
// as they were when it started (their writer takes its result before it writes them again). A loop is accepted
// when two consecutive keyframes of the segment find it with the same correction (zero false closures is the
// rule). It then becomes an edge of the pose graph over every place keyframe, solved on another thread while frames
// go on (LoopCorrection); at a frame boundary the map takes the solution. In a map whose unit is not metric (one
// camera) a loop is a similarity: its scale comes from the keyframe's own points against the place's
// (loopScale), and the graph is over Sim(3). Fixed memory.
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/core/background_task.hpp"
#include "mcslam/places/loop_correction.hpp"
#include "mcslam/places/loop_scale.hpp"
#include "mcslam/places/place_map.hpp"
#include "mcslam/places/places_options.hpp"
#include "mcslam/places/relocalizer.hpp"

namespace mcslam {

struct LoopStats {
  uint64_t queries = 0;
  uint64_t verified = 0;    // candidates that passed verification (before the consistency check)
  uint64_t consistent = 0;  // confirmed, but the map already agreed with them within their uncertainty
  uint64_t closures = 0;    // accepted: the map was corrected
  uint64_t merges = 0;      // closures that joined two segments
  uint64_t skipped = 0;     // keyframes not queried: a correction was being solved
  uint64_t waits = 0;       // detections a frame had to wait for before writing the map
  uint64_t restarted = 0;   // corrections solved again: a segment was moved or rescaled during the solve
  // Loops onto places made while the unit was uncertain (PlaceUnit): the place keyframes' cameras whose points took
  // the unit a loop measured on them, and the loops not closed because the recognizing keyframe's own unit was
  // uncertain too.
  uint64_t places_rescaled = 0;
  uint64_t units_unmeasured = 0;
  uint64_t remeasured = 0;  // loops measured again at once, on the places that took the keyframe's unit
  int64_t last_keyframe = -1, last_candidate = -1;  // place keyframe ids of the last closure
  double last_correction_m = 0, last_correction_deg = 0;
  double last_solve_ms = 0;
};

// The map file's loops part: the loops, then each of the map's segments' root (which segment the loops joined it
// to). takeLoops() fills `loops` and `roots` (sized by the caller; `roots` at least `segments`) and returns the
// loop count; InputError from `in` for more loops than `loops` holds or a root that is no union. `with_scales`: the
// loops have their scales (map files from version 2).
void putLoops(ByteWriter& out, std::span<const LoopEdge> loops, std::span<const int32_t> roots);
int takeLoops(ByteReader& in, int segments, std::span<LoopEdge> loops, std::span<int32_t> roots,
              bool with_scales = true);
std::size_t loopFileBytes(bool with_scales = true);  // one loop in putLoops' output

class LoopCloser {
 public:
  // `similarity`: the rig's maps have no metric unit (one camera): loops are closed in Sim(3).
  LoopCloser(const Rig& rig, const PlacesOptions& options, float scale_factor, int max_features_per_camera,
             bool similarity = false);
  bool similarity() const { return correction_.similarity(); }

  // The extrinsics the next detection projects with. Not while a detection is in flight.
  void setRig(const Rig& rig);
  // Keyframe `slot` was just added to `map`, with its words to `database` (`features`: the frame it was made of;
  // `own_points`: its own point of each keypoint as loopScale() takes them, for a loop's scale): starts
  // looking for a loop it closes on the detection thread (copying `features`, `words` and `own_points`). Until
  // collectDetection() took the result, `map` and `database` must not be written, nor another detection started.
  void startDetection(int slot, const FrameFeatures& features, const FrameWords& words, const PlaceMap& map,
                      const PlaceDatabase& database, std::span<const Eigen::Vector3f> own_points = {});
  // Takes the result of the detection in flight, waiting for it with `wait` (otherwise only when it is ready), and
  // decides on it: true when it closed a loop, whose correction is then being solved; the map does not move until
  // takeCorrection(). `map` is the one the detection started on, unchanged; a loop onto places whose unit was
  // uncertain may give their points the unit it measured (settlePlaceUnits) and measure the loop again on them: with
  // `wait` that is waited for too; without, it is in flight when this returns.
  bool collectDetection(PlaceMap& map, bool wait);
  // At a frame boundary: a correction solved since moves the map's keyframes and segments' frames (true). With
  // `wait`, one in flight is waited for; without, it is taken at the first call that finds it ready.
  bool takeCorrection(PlaceMap& map, bool wait);
  bool correcting() const { return correction_.running() || correction_wanted_; }
  // By the detection and correction threads; any thread may ask.
  uint64_t threadAllocations() const { return correction_.threadAllocations() + detection_task_.allocations(); }
  const LoopStats& stats() const { return stats_; }
  int loops() const { return loop_count_; }
  std::span<const LoopEdge> loopEdges() const { return {loops_.data(), static_cast<std::size_t>(loop_count_)}; }
  // `map` rescaled the keyframes of `segment` made from `from_frame` on by `s` (PlaceMap::rescaleSegment): a loop
  // between two of them was measured in the unit they had, and takes theirs. (Sim(3) loops are kept in their
  // keyframes' units already.)
  void followRescale(const PlaceMap& map, int32_t segment, double s, uint64_t from_frame);
  void clear();  // waits for a detection in flight and drops it
  // The segment that stands for all those loops have joined to `segment`.
  int32_t root(int32_t segment) { return findRoot(segment); }
  // No loop joined `segment` to another (it may be reused for a new one).
  bool alone(int32_t segment);

  // The map file's part: the loops and which segments they joined. read() replaces them (InputError from `in` for
  // a file that does not fit max_loops or the map's `segments`).
  void write(ByteWriter& out, int segments) const;
  void read(ByteReader& in, int segments, bool with_scales = true);
  std::size_t maxWrittenBytes() const;

 private:
  // The job of the detection thread: the query and verification of the keyframe being detected.
  struct Detection final : BackgroundJob {
    void run() override { closer->detect(); }
    LoopCloser* closer = nullptr;
  };

  void detect();
  // What the detection found for keyframe `slot` decides whether it closes a loop (onto the processing thread).
  bool decide(int slot, const RelocalizationResult& found, PlaceMap& map);
  enum class GroupUnits {
    Agree,         // the loop's places are in this keyframe's unit, or their points took it within its error
    Differ,        // some were in another: their points took the measured unit, the loop's pose is off
    Unmeasurable,  // some are of uncertain unit, and so is this keyframe
  };
  GroupUnits settlePlaceUnits(int slot, PlaceMap& map);
  bool matched(int place, int cam) const;  // an inlier of the last verification is camera `cam`'s of `place`
  // Starts measuring keyframe `slot`'s loop again (false: it was already).
  bool remeasure(int slot);
  // The place keyframe (slot) of the verified group whose points hold the most inliers (the candidate first).
  int measuringPlace() const;
  bool followsLast(int slot, const PlaceMap& map) const;
  bool consistentWithLast(int slot, const PlaceMap& map, const SE3& correction) const;
  bool consistentWithLast(int slot, const PlaceMap& map, const Sim3& correction, const LoopScale& scale) const;
  bool closesALoop(const PlaceMap& map, int candidate, int slot) const;
  // Starts solving the pose graph of the whole map with the loops so far (LoopCorrection).
  void startCorrection(const PlaceMap& map);
  int32_t findRoot(int32_t segment);

  PlacesOptions options_;
  Relocalizer verifier_;
  std::vector<LoopEdge> loops_;
  int loop_count_ = 0;
  std::vector<int32_t> segment_root_;  // union-find over segments joined by loops
  std::vector<int32_t> roots_;         // scratch of startCorrection(): each segment's root
  LoopCorrection correction_;
  std::vector<Vec3> camera_centers_;  // of the rig the detections project with, in the body frame
  bool correction_wanted_ = false;    // a loop was accepted (or a solve went stale): solve (again)
  // The last accepted loop, for the log when its correction lands.
  struct Accepted {
    int64_t keyframe = -1, candidate = -1;
    Timestamp t_keyframe = 0, t_candidate = 0;
    int inliers = 0;
    SE3 correction;
  } accepted_;
  // The last verified detection, waiting for the next keyframe to confirm it.
  int64_t pending_keyframe_ = -1;
  int32_t pending_segment_ = -1;
  int64_t pending_candidate_ = -1;
  SE3 pending_correction_;
  Sim3 pending_similarity_correction_;
  LoopScale pending_scale_;
  LoopStats stats_;
  // The detection in flight: its keyframe, the map and database it reads, copies of the keyframe's frame and words,
  // and what it found.
  int detect_slot_ = -1;
  int64_t detect_keyframe_id_ = -1;
  int64_t remeasured_keyframe_ = -1;  // the keyframe whose loop was last measured again (remeasure)
  const PlaceMap* detect_map_ = nullptr;
  const PlaceDatabase* detect_database_ = nullptr;
  FrameFeatures detect_features_;
  FrameWords detect_words_;
  int features_per_camera_ = 0;
  std::vector<Eigen::Vector3f> detect_own_points_;  // the keyframe's own points by keypoint (a loop's scale)
  std::vector<double> scale_scratch_;
  RelocalizationResult found_;
  LoopScale found_scale_;
  Detection detection_;
  BackgroundTask detection_task_;  // last: stops (after the job in flight) before what the job uses goes
};

}  // namespace mcslam
