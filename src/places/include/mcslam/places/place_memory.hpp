#pragma once
// Place memory of the SLAM: the place map of the robot's whole life, kept beside the odometry. After the odometry
// processed a frame, PlaceMemory adds the keyframes it settled to the place map (with their points and their words
// in the database), relocalizes the frame when the odometry lost it (all cameras query the database; generalized
// P3P verifies), and puts the estimate into the world frame: T_w_b = T_w_o(segment) * T_o_b (docs/design/places.md).
// Fixed memory: everything is sized at construction; processing a frame allocates nothing.
#include <cstdint>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/odometry/odometry.hpp"
#include "mcslam/places/loop_closer.hpp"
#include "mcslam/places/place_map.hpp"
#include "mcslam/places/places_options.hpp"
#include "mcslam/places/relocalizer.hpp"
#include "mcslam/recognition/bow_vector.hpp"
#include "mcslam/recognition/place_database.hpp"
#include "mcslam/recognition/vocabulary.hpp"

namespace mcslam {

struct PlaceStats {
  uint64_t keyframes = 0;                  // added to the place map
  uint64_t keyframes_dropped = 0;          // not added: the map was full
  uint64_t relocalization_queries = 0;     // lost frames that queried the database
  uint64_t relocalizations = 0;            // ... and were found
  int64_t last_relocalized_keyframe = -1;  // id of the place keyframe the last relocalization verified on
  int64_t last_relocalized_frame = -1;     // frame index of the last relocalization
};

class PlaceMemory {
 public:
  // `vocabulary` must outlive the place memory.
  PlaceMemory(const Rig& rig, const Vocabulary& vocabulary, const PlacesOptions& options,
              const OdometryOptions& odometry_options, int max_features_per_camera);

  // After odometry.process(frame, frame_index, out): see above. `out` ends in the world frame.
  void afterOdometry(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry, PoseEstimate& out);

  const PlaceMap& map() const { return map_; }
  const PlaceStats& stats() const { return stats_; }
  // The segment the odometry's current map belongs to (-1 before the first map).
  int32_t segment() const { return segment_; }
  const LoopStats& loopStats() const { return loop_closer_.stats(); }
  // Times the world estimate moved (loop closures, merges); PoseEstimate::world_revision carries it.
  uint16_t worldRevision() const { return world_revision_; }

 private:
  void followSegment(const Odometry& odometry);
  void addKeyframe(const Odometry& odometry, int odometry_slot);
  void relocalize(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry, PoseEstimate& out);

  const Vocabulary& vocabulary_;
  PlacesOptions options_;
  PlaceMap map_;
  PlaceDatabase database_;
  FrameWords words_;
  Relocalizer relocalizer_;
  LoopCloser loop_closer_;
  std::vector<MapSeed> seeds_;
  std::vector<int64_t> landmark_stamp_;  // per odometry landmark slot: the keyframe id it was last added for
  int32_t segment_ = -1;
  uint64_t initializations_seen_ = 0;
  uint16_t world_revision_ = 0;
  PlaceStats stats_;
};

}  // namespace mcslam
