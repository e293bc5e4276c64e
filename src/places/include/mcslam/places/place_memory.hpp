#pragma once
// Place memory of the SLAM: the place map of the robot's whole life, kept beside the odometry. After the odometry
// processed a frame, PlaceMemory adds the keyframes it settled to the place map (with their points and their words
// in the database), relocalizes the frame when the odometry lost it (all cameras query the database; generalized
// P3P verifies), and puts the estimate into the world frame: T_w_b = T_w_o(segment) * T_o_b (docs/design/places.md).
// A run that reuses a saved map (readMap) is placed in the map's world when the rig is first recognized in it;
// until then its poses are not published as valid (TrackingState::Localizing).
// Fixed memory: everything is sized at construction; processing a frame allocates nothing.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/odometry/odometry.hpp"
#include "mcslam/places/loop_closer.hpp"
#include "mcslam/places/map_file.hpp"
#include "mcslam/places/place_map.hpp"
#include "mcslam/places/places_options.hpp"
#include "mcslam/places/relocalizer.hpp"
#include "mcslam/recognition/bow_vector.hpp"
#include "mcslam/recognition/place_database.hpp"
#include "mcslam/recognition/vocabulary.hpp"

namespace mcslam {

struct PlaceStats {
  uint64_t keyframes = 0;                  // added to the place map
  uint64_t keyframes_dropped = 0;          // not added: the map was full and none could go
  uint64_t keyframes_culled = 0;           // left the full map to make room (PlaceMap::leastNeededKeyframe)
  uint64_t relocalization_queries = 0;     // lost frames that queried the database
  uint64_t relocalizations = 0;            // ... and were found
  int64_t last_relocalized_keyframe = -1;  // id of the place keyframe the last relocalization verified on
  int64_t last_relocalized_frame = -1;     // frame index of the last relocalization
  int64_t placed_frame = -1;               // with a reused map: the frame first recognized in it
  uint64_t localization_corrections = 0;   // localizing in a map: recognitions that moved the estimate
  uint64_t segments_reused = 0;            // all PlaceMap::kMaxSegments taken: an empty one made anew
  uint64_t places_refined = 0;             // places of an uncertain unit that took their points and pose again
};

class PlaceMemory {
 public:
  // `vocabulary` must outlive the place memory.
  PlaceMemory(const Rig& rig, const Vocabulary& vocabulary, const PlacesOptions& options,
              const OdometryOptions& odometry_options, int max_features_per_camera);

  // After odometry.process(frame, frame_index, out): see above. `out` ends in the world frame.
  void afterOdometry(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry, PoseEstimate& out);
  // A pose of the odometry's current map in the world frame (afterOdometry() moves the frame's with it); false while
  // that map has no place in the world yet (localizing in a loaded map).
  bool toWorld(const SE3& T_o_b, SE3& T_w_b) const;
  // Takes the loop closer's work still in flight (a detection, then a correction) into the map (after the last
  // frame, before reading the map).
  void flush() {
    collectLoopDetection(/*wait=*/true);
    takeCorrection(/*wait=*/true);
  }
  uint64_t threadAllocations() const { return loop_closer_.threadAllocations(); }  // by the loop closer's threads

  const PlaceMap& map() const { return map_; }
  const PlaceStats& stats() const { return stats_; }
  // The segment the odometry's current map belongs to (-1 before the first map).
  int32_t segment() const { return segment_; }
  const LoopStats& loopStats() const { return loop_closer_.stats(); }
  // Times the world estimate moved (loop closures, merges); PoseEstimate::world_revision carries it.
  uint16_t worldRevision() const { return world_revision_; }

  // The map file (map_file.hpp) of the place map, in `out`; allocates nothing when `out` has maxMapBytes()
  // reserved.
  void writeMap(std::string& out) const;
  std::size_t maxMapBytes() const;
  // Replaces the place map by the file's (`bytes` of the file `name`), before the first frame; with
  // `localize_only` the run only localizes in it and never changes it. InputError naming the file for one that is
  // not a map, was made for another rig or vocabulary, or exceeds the capacities.
  void readMap(std::string_view bytes, const std::string& name, bool localize_only = false);
  bool mapLoaded() const { return loaded_; }

 private:
  // A place of an uncertain unit whose keyframe is still in the odometry's window (refinePlaces), by slot and id in
  // either map.
  struct UnrefinedPlace {
    int place_slot = -1, odometry_slot = -1;
    int64_t place_id = -1, odometry_id = -1;
  };

  // A loop correction solved since the last frame moves the map (PlacesOptions::repeatable: waiting for it).
  void takeCorrection(bool wait);
  // This frame (the odometry's output) writes neither the place map nor the database: it only tracked, in a placed
  // segment, and settled, rescaled, began and refined nothing.
  bool onlyReadsMap(const Odometry& odometry, const PoseEstimate& out) const;
  void collectLoopDetection(bool wait);
  void followSegment(const Odometry& odometry);
  int32_t reuseSegment(const SE3& T_w_o, bool placed);  // -1 when none can be
  void addKeyframe(const Odometry& odometry, int odometry_slot);
  // Place keyframe `slot`'s points: those of odometry keyframe `kf` whose position is certain, in its body frame.
  // `own` (empty, or cam * max features + kp): each keypoint's point, for a loop's scale.
  void gatherPoints(const Map& local, const Rig& rig, const Keyframe& kf, int slot, std::span<Eigen::Vector3f> own);
  // The places waiting for their keyframe to leave the odometry's window take its points and pose then.
  void refinePlaces(const Odometry& odometry);
  bool refinementDue(const Odometry& odometry) const;  // a waiting place's keyframe has left the window
  bool stillUnrefined(const Map& local, const UnrefinedPlace& u) const;  // both keyframes still there
  void makeRoom();  // a full map lets its least needed keyframe go, keeping those loops join
  void relocalize(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry, PoseEstimate& out);
  // The tracked frame recognized in the map's other segments places the run in the world, or (localizing in a
  // map) corrects the current segment's T_w_o.
  void place(const FrameFeatures& frame, uint64_t frame_index, const Odometry& odometry, const SE3& T_o_b);
  bool enterWorld(uint64_t frame_index);
  // The odometry goes on at T_w_b from the relocalizer's last inliers, in the current segment's frame; false (and
  // `out` lost) when it could not.
  bool resumeOdometry(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry, const SE3& T_w_b,
                      PoseEstimate& out);
  // After a loop: segments joined to a placed one are placed, and those joined to an anchored one anchored.
  void propagatePlacement();

  const Vocabulary& vocabulary_;
  PlacesOptions options_;
  PlaceMap map_;
  PlaceDatabase database_;
  FrameWords words_;
  Relocalizer relocalizer_;
  LoopCloser loop_closer_;
  std::vector<MapSeed> seeds_;
  std::vector<Vec3> camera_centers_;  // in the body frame, as of the odometry's last rescale (PlaceMap::rescaleSegment)
  std::vector<int64_t> landmark_stamp_;  // per odometry landmark slot: the gather it was last added in
  // The last keyframe's own point of each keypoint (cam * max features + kp; NaN: none), for the scale of a loop
  // (LoopScale).
  std::vector<Eigen::Vector3f> own_points_;
  int features_per_camera_ = 0;
  int64_t gather_stamp_ = 0;               // one per gatherPoints()
  std::vector<UnrefinedPlace> unrefined_;  // waiting for their keyframe to leave the window; fixed capacity
  std::size_t unrefined_count_ = 0;
  int32_t segment_ = -1;
  uint64_t initializations_seen_ = 0;
  uint16_t world_revision_ = 0;
  bool loaded_ = false;
  bool localize_only_ = false;
  int64_t landmark_id_offset_ = 0;  // past the loaded map's: this run's landmark ids continue after them
  int last_place_keyframe_ = -1;    // slot of the keyframe the last placement verified on
  // Placement: the last recognition's T_w_o, waiting for the next one to confirm it; the odometry's path so far.
  bool pending_fix_ = false;
  SE3 pending_T_w_o_;
  double pending_path_ = 0;
  double path_ = 0, path_at_fix_ = 0;
  Vec3 last_position_ = Vec3::Zero();
  bool have_last_position_ = false;
  BowVector file_words_;           // scratch of readMap()
  std::vector<int64_t> kept_ids_;  // scratch of makeRoom(): the loops' keyframes, sorted
  // Per segment: its place in the world was measured (the run's first map, a map file's, one recognized in the
  // map or joined to an anchored one by a loop), not guessed by the motion model across a loss.
  std::vector<uint8_t> anchored_;
  std::vector<uint8_t> root_placed_, root_anchored_;  // scratch of propagatePlacement(), per segment
  std::vector<MapFileHeader::Camera> cameras_;
  mutable MapFileHeader file_header_;  // scratch of writeMap(), its cameras sized at construction
  uint32_t vocabulary_fingerprint_ = 0;
  PlaceStats stats_;
};

}  // namespace mcslam
