#pragma once
// The place map: the map of the robot's whole life, in fixed memory. A pool of place keyframes, each with its world
// pose, the odometry pose it was made at and its segment, and its points anchored in its own body frame (position,
// descriptor, camera, the vocabulary node the descriptor falls in, the odometry's landmark id); points are kept
// sorted by node, so that matching a frame against a keyframe compares only descriptors of the same node. A
// segment is a stretch of odometry in one frame `o`; the map knows each segment's T_w_o and, for a map whose unit
// is not metric (one camera), the scale from its odometry's unit to the world's, which loop closures in Sim(3)
// change (1 otherwise). Slots are recycled, ids never. Nothing is allocated after construction.
//
// One writer: PlaceMemory (and the map file reader). Readers get const views for a call.
#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/core/binary_io.hpp"
#include "mcslam/core/se3.hpp"
#include "mcslam/core/sim3.hpp"
#include "mcslam/core/time.hpp"
#include "mcslam/features/keypoint.hpp"
#include "mcslam/places/places_options.hpp"

namespace mcslam {

struct PlacePoint {
  Eigen::Vector3f p_k = Eigen::Vector3f::Zero();  // in the keyframe's body frame, in the world's unit
  int32_t node = 0;                               // vocabulary node of the descriptor (FrameWords::node)
  int16_t cam = -1;                               // camera of the keyframe that observed it
  int8_t octave = 0;
  int64_t landmark_id = -1;  // the odometry's landmark (ids are unique over the run)
  Descriptor descriptor{};
};

struct PlaceKeyframe {
  bool alive = false;
  int64_t id = -1;
  int32_t segment = -1;
  Timestamp t = 0;
  uint64_t frame_index = 0;
  SE3 T_w_k;  // world pose (moved by loop closures)
  SE3 T_o_k;  // pose in its segment's odometry frame when it was made
  // World units per odometry unit at this keyframe: its segment's scale when it was made, times what Sim(3) loop
  // closures scaled it by since (1 in a metric map). The odometry's motion to the next keyframe, times this, is
  // that motion in the world's unit.
  double unit = 1.0;
  // Relative standard deviation of the odometry's unit over the motion from the previous keyframe to this one
  // (Odometry::unitSigma when it was made): 0 for a rig whose maps start metric. The loop closer's graph lets that
  // motion's length, not its direction, give way by this much.
  double unit_sigma = 0;
  // Bit c: its points of camera c took the unit a loop measured on them (LoopCloser; only places of an uncertain
  // unit_sigma are measured). Not in the map file: a run that loads the map measures them again, in its own unit.
  uint64_t cameras_unit_measured = 0;
  int32_t previous = -1, next = -1;  // neighbours in its segment (slots)
  int32_t point_count = 0;
};

// What a map file holds beyond version 1's, by its version (MapFileHeader::kVersion).
struct MapFileFields {
  bool scales = true;       // 2: segments' scales, keyframes' units, loops' scales (Sim(3) loop closure)
  bool unit_sigmas = true;  // 3: keyframes' unit sigmas
  static MapFileFields ofVersion(uint32_t version) { return {version >= 2, version >= 3}; }
};

class PlaceMap {
 public:
  // Each odometry map of each run is a segment (a map reused over many runs gains one per run).
  static constexpr int kMaxSegments = 1024;

  PlaceMap(int max_keyframes, int max_points_per_keyframe);

  void clear();
  int capacity() const { return static_cast<int>(keyframes_.size()); }
  int maxPointsPerKeyframe() const { return max_points_; }
  int size() const { return live_; }

  // A new keyframe at the end of `segment` (slot, or -1 when the pool is full). Its points are added with
  // addPoint() and then sorted by finishKeyframe().
  int createKeyframe(int32_t segment, Timestamp t, uint64_t frame_index, const SE3& T_w_k, const SE3& T_o_k);
  void setUnitSigma(int slot, double sigma) { keyframes_[static_cast<std::size_t>(slot)].unit_sigma = sigma; }
  bool addPoint(int slot, const PlacePoint& point);  // false when the keyframe holds its maximum
  int slotOfId(int64_t id) const;                    // the live keyframe's, or -1 (a scan of the pool)
  void finishKeyframe(int slot);
  void eraseKeyframe(int slot);  // its neighbours become each other's
  // The keyframe a full map can best do without (slot, -1 when none may go): the one whose neighbours in its
  // segment lie closest together, in translation and in rotation, each measured against the map's typical gap; so
  // that where the rig lingered or went slowly is thinned first and the path stays covered. A segment's ends stay
  // (they hold the segment's frame and its joins), and so do the keyframes whose ids are in `kept` (sorted).
  int leastNeededKeyframe(std::span<const int64_t> kept) const;

  const PlaceKeyframe& keyframe(int slot) const { return keyframes_[static_cast<std::size_t>(slot)]; }
  void setKeyframePose(int slot, const SE3& T_w_k) { keyframes_[static_cast<std::size_t>(slot)].T_w_k = T_w_k; }
  // A Sim(3) loop correction scaled the keyframe's surroundings by `s`: its unit and points follow, each point's
  // depth from the camera that saw it (`camera_centers`: each camera's centre in the body frame; a point of a camera
  // not in it scales about the body).
  void scaleKeyframe(int slot, double s, std::span<const Vec3> camera_centers);
  // Keyframe `slot`'s points (of camera `cam`, or all: -1) take a unit `s` times the one they were in (a loop
  // measured it), as scaleKeyframe's; its pose and unit stay.
  void scalePoints(int slot, double s, std::span<const Vec3> camera_centers, int cam = -1);
  // The odometry refined keyframe `slot`'s pose in its segment to T_o_k: its world pose takes the same change in its
  // body frame (and keeps what loop corrections moved it by).
  void refinePose(int slot, const SE3& T_o_k);
  // Keyframe `slot` takes its points anew (addPoint, then finishKeyframe), none of them measured.
  void clearPoints(int slot) {
    keyframes_[static_cast<std::size_t>(slot)].point_count = 0;
    keyframes_[static_cast<std::size_t>(slot)].cameras_unit_measured = 0;
  }
  // As scalePoints for camera `cam`'s points, for the unit a loop measured on them: marks them
  // (PlaceKeyframe::cameras_unit_measured).
  void takeMeasuredUnit(int slot, int cam, double s, std::span<const Vec3> camera_centers) {
    scalePoints(slot, s, camera_centers, cam);
    if (cam >= 0 && cam < 64) keyframes_[static_cast<std::size_t>(slot)].cameras_unit_measured |= uint64_t{1} << cam;
  }
  // The segment's odometry took a new unit (positions p became center + s (p - center) in its frame) for the motion
  // since frame `from_frame`: the keyframes made from then on follow (their odometry and world poses, about the
  // center in either frame, and their points as scaleKeyframe's); those made before keep their poses, so that the
  // motion between them keeps its length (the motion of a map whose unit drifted was right when it was made; a map
  // whose unit was arbitrary rescales all of it, from frame 0).
  void rescaleSegment(int32_t segment, double s, const Vec3& center, uint64_t from_frame,
                      std::span<const Vec3> camera_centers);
  std::span<const PlacePoint> points(int slot) const {
    return {points_.data() + static_cast<std::size_t>(slot) * static_cast<std::size_t>(max_points_),
            static_cast<std::size_t>(keyframes_[static_cast<std::size_t>(slot)].point_count)};
  }
  // Points of keyframe `slot` whose node is `node` (they are contiguous).
  std::span<const PlacePoint> pointsOfNode(int slot, int32_t node) const;
  int newestKeyframe() const { return newest_; }  // slot, -1 when empty

  // Segments: T_w_o of each, and whether it is placed in the world. A run's first map defines the world and one
  // started after a loss continues the frame the odometry coasted in: both are placed. The first map of a run
  // that reuses a saved map is not, until the rig is recognized in the saved map (moveSegment) or a loop joins it.
  // `continues`: the segment whose frame this one's continues (the odometry coasted from it), -1 for none; kept in
  // memory only, for a loop correction that lands after the new segment began (LoopCloser).
  int32_t createSegment(const SE3& T_w_o, bool placed = true, int32_t continues = -1);  // -1 when kMaxSegments
  // With every segment taken, one that holds no keyframe is made anew (as createSegment would make it); segments
  // that continued it no longer continue anything.
  void reuseSegment(int32_t segment, const SE3& T_w_o, bool placed, int32_t continues);
  bool hasKeyframes(int32_t segment) const { return newest_of_segment_[static_cast<std::size_t>(segment)] >= 0; }
  int32_t continuesFrom(int32_t segment) const { return segment_continues_[static_cast<std::size_t>(segment)]; }
  int segments() const { return segment_count_; }
  const SE3& segmentPose(int32_t segment) const { return segment_T_w_o_[static_cast<std::size_t>(segment)]; }
  void setSegmentPose(int32_t segment, const SE3& T_w_o) { segment_T_w_o_[static_cast<std::size_t>(segment)] = T_w_o; }
  // World units per unit of the segment's odometry (1 until a Sim(3) loop closure corrects the unit).
  double segmentScale(int32_t segment) const { return segment_scale_[static_cast<std::size_t>(segment)]; }
  void setSegmentScale(int32_t segment, double s) { segment_scale_[static_cast<std::size_t>(segment)] = s; }
  // The segment's frame as a similarity: odometry coordinates to world coordinates.
  Sim3 segmentSimilarity(int32_t segment) const { return Sim3(segmentPose(segment), segmentScale(segment)); }
  // A pose of the segment's odometry in the world, and back.
  SE3 toWorld(int32_t segment, const SE3& T_o_b) const;
  SE3 toOdometry(int32_t segment, const SE3& T_w_b) const;
  // The segment's T_w_o that puts the odometry's pose T_o_b at T_w_b, keeping its scale.
  SE3 segmentPoseFor(int32_t segment, const SE3& T_w_b, const SE3& T_o_b) const;
  bool placed(int32_t segment) const { return segment_placed_[static_cast<std::size_t>(segment)] != 0; }
  void setPlaced(int32_t segment) { segment_placed_[static_cast<std::size_t>(segment)] = 1; }
  // The segment, as one rigid piece, now has T_w_o: its keyframes follow (a segment no loop has bent yet).
  void moveSegment(int32_t segment, const SE3& T_w_o);
  // Times a segment was moved or rescaled as a whole (moveSegment, rescaleSegment, read, clear): a pose-graph
  // solution computed from the poses before is stale.
  uint64_t reshapes() const { return reshapes_; }

  // The map file's part of the place map: segments and live keyframes with their points, in slot order. read()
  // replaces the map by the file's, its keyframes in slots 0.. in that order; a file that does not fit the capacities,
  // or whose points name a camera beyond `cameras`, is refused (InputError from `in`).
  void write(ByteWriter& out) const;
  // `fields`: what the file's version holds (a map file before version 2 has no scales: its maps are metric; before
  // version 3 no unit sigmas: its keyframes read as made in a unit that was known).
  void read(ByteReader& in, int cameras, MapFileFields fields = {});
  // Bytes write() needs at most for this map's capacities; bytes one keyframe (without its points) and one point
  // take in it.
  std::size_t maxWrittenBytes() const;
  static std::size_t keyframeFileBytes(MapFileFields fields = {});
  static std::size_t pointFileBytes();
  int64_t nextId() const { return next_id_; }

 private:
  std::vector<PlaceKeyframe> keyframes_;
  std::vector<PlacePoint> points_;  // max_points_ per keyframe slot
  std::vector<int32_t> free_;
  int free_count_ = 0;
  int live_ = 0;
  int max_points_ = 0;
  int newest_ = -1;
  int64_t next_id_ = 0;
  std::vector<int32_t> newest_of_segment_;
  std::vector<SE3> segment_T_w_o_;
  std::vector<double> segment_scale_;
  std::vector<uint8_t> segment_placed_;
  std::vector<int32_t> segment_continues_;
  uint64_t reshapes_ = 0;
  mutable std::vector<int32_t> file_position_;  // scratch of write() and read(), one per slot

  void checkChains(const ByteReader& in);
  void setUpSegment(int32_t segment, const SE3& T_w_o, bool placed, int32_t continues);
  int segment_count_ = 0;
};

}  // namespace mcslam
