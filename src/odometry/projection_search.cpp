#include "mcslam/odometry/projection_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "mcslam/features/octave_scales.hpp"
#include "mcslam/odometry/landmark_tracks.hpp"

namespace mcslam {

void FrameMatches::allocate(int cameras, int capacity, int max_landmarks) {
  cameras_ = cameras;
  lm_.assign(cameras, std::vector<int32_t>(capacity, -1));
  dist_.assign(cameras, std::vector<int16_t>(capacity, 0));
  kp_of_.assign(static_cast<std::size_t>(max_landmarks) * cameras, -1);
}

void FrameMatches::reset(const FrameFeatures& f) {
  for (int c = 0; c < cameras_; ++c) std::fill(lm_[c].begin(), lm_[c].begin() + f.sets[c].count, -1);
  std::fill(kp_of_.begin(), kp_of_.end(), -1);
  count_ = 0;
}

void FrameMatches::clear(int cam, int kp) {
  const int lm = lm_[cam][kp];
  if (lm < 0) return;
  kp_of_[static_cast<std::size_t>(lm) * cameras_ + cam] = -1;
  lm_[cam][kp] = -1;
  --count_;
}

bool FrameMatches::offer(int cam, int kp, int lm, int distance) {
  const int held = lm_[cam][kp];
  if (held == lm) return false;
  if (held >= 0 && dist_[cam][kp] <= distance) return false;
  const int other = kp_of_[static_cast<std::size_t>(lm) * cameras_ + cam];
  if (other >= 0 && dist_[cam][other] <= distance) return false;
  if (held >= 0) clear(cam, kp);
  if (other >= 0) clear(cam, other);
  lm_[cam][kp] = lm;
  dist_[cam][kp] = static_cast<int16_t>(distance);
  kp_of_[static_cast<std::size_t>(lm) * cameras_ + cam] = kp;
  ++count_;
  return true;
}

ProjectionSearch::ProjectionSearch(const Rig& rig, int max_features_per_camera) : T_c_w_(rig.size()) {
  for (const RigCamera& c : rig.cameras) {
    grids_.emplace_back(c.model.width(), c.model.height(), 24, max_features_per_camera);
    cos_field_.push_back(std::cos(std::min(M_PI, c.model.imageHalfAngle() + M_PI / 180.0)));  // a degree of margin
  }
}

void ProjectionSearch::prepare(const FrameFeatures& frame) {
  for (int c = 0; c < frame.cameras(); ++c) grids_[c].build(frame.sets[c]);
}

int ProjectionSearch::search(const Map& map, const Rig& rig, const int32_t* slots, int n, const SE3& T_w_b,
                             const FrameFeatures& frame, const ProjectionSearchParams& p, FrameMatches& matches,
                             LandmarkTracks* count_visible) {
  const int cams = frame.cameras();
  for (int c = 0; c < cams; ++c) T_c_w_[c] = (T_w_b * rig.T_b_c(c)).inverse();
  const float log_scale = std::log(p.scale_factor);
  const OctaveScales scales(p.scale_factor);
  const int c_begin = p.camera >= 0 ? p.camera : 0, c_end = p.camera >= 0 ? std::min(p.camera + 1, cams) : cams;
  int made = 0;
  predicted_ = 0;
  for (int i = 0; i < n; ++i) {
    const int lm = slots[i];
    const Landmark& l = map.landmark(lm);
    if (!l.alive) continue;
    bool visible = false;
    for (int c = c_begin; c < c_end; ++c) {
      const bool searched = frame.present[c] && matches.keypointOf(lm, c) < 0;
      const Vec3 p_c = T_c_w_[c] * l.p_w;
      if (p_c.z() < cos_field_[c] * p_c.norm()) continue;  // outside the camera's field of view
      Vec2 uv;
      const CameraModel& model = rig.model(c);
      if (!model.project(p_c, uv) || !model.inImage(uv, 2.0)) continue;
      // Octave the point should be found at, from its distance (ORB-SLAM's scale prediction).
      const double dist = p_c.norm();
      int predicted = 0;
      if (p.check_scale && l.max_distance > 0) {
        if (dist > 1.2 * l.max_distance || dist < 0.8 * l.min_distance) continue;
        predicted =
            std::clamp(static_cast<int>(std::ceil(std::log(l.max_distance / dist) / log_scale)), 0, p.levels - 1);
      }
      ++predicted_;
      if (!searched) continue;
      visible = true;
      const double radius = p.radius_px * scales[predicted];
      const double r2 = radius * radius;
      const FeatureSet& set = frame.sets[c];
      int best = 257, second = 257, best_kp = -1, best_octave = 0, second_octave = 0;
      grids_[c].forEachNear(uv.x(), uv.y(), radius, [&](const KeypointGrid::Entry& kp) {
        if (p.check_scale && l.max_distance > 0 && (kp.octave < predicted - 1 || kp.octave > predicted + 1)) return;
        const double dx = kp.x - uv.x(), dy = kp.y - uv.y();
        if (dx * dx + dy * dy > r2) return;
        const int d = hammingDistance(l.descriptor, set.descriptors[kp.index]);
        if (d < best) {
          second = best;
          second_octave = best_octave;
          best = d;
          best_kp = kp.index;
          best_octave = kp.octave;
        } else if (d < second) {
          second = d;
          second_octave = kp.octave;
        }
      });
      if (best_kp < 0 || best > p.max_hamming) continue;
      if (best_octave == second_octave && !passesRatioTest(best, second, p.ratio)) continue;
      if (matches.offer(c, best_kp, lm, best)) ++made;
    }
    if (visible && count_visible) ++count_visible->of(map, lm).visible;
  }
  return made;
}

int ProjectionSearch::searchByDescriptor(const Map& map, const int32_t* slots, int n, const FrameFeatures& frame,
                                         int max_hamming, float ratio, FrameMatches& matches) {
  int made = 0;
  for (int i = 0; i < n; ++i) {
    const int lm = slots[i];
    const Landmark& l = map.landmark(lm);
    if (!l.alive) continue;
    // The best keypoint over all cameras: the rig may have turned the point into another camera.
    int best = 257, second = 257, best_cam = -1, best_kp = -1;
    for (int c = 0; c < frame.cameras(); ++c) {
      if (!frame.present[c]) continue;
      const FeatureSet& set = frame.sets[c];
      for (int k = 0; k < set.count; ++k) {
        const int d = hammingDistance(l.descriptor, set.descriptors[k]);
        if (d < best) {
          // A second keypoint of the same point in another camera is no ambiguity.
          if (best_cam != c && best_cam >= 0 && frame.mv_of[best_cam][best_kp] >= 0 &&
              frame.mv_of[best_cam][best_kp] == frame.mv_of[c][k]) {
          } else {
            second = best;
          }
          best = d;
          best_cam = c;
          best_kp = k;
        } else if (d < second) {
          const bool same_point = frame.mv_of[c][k] >= 0 && frame.mv_of[c][k] == frame.mv_of[best_cam][best_kp];
          if (!same_point) second = d;
        }
      }
    }
    if (best_kp < 0 || best > max_hamming || !passesRatioTest(best, second, ratio)) continue;
    if (matches.offer(best_cam, best_kp, lm, best)) ++made;
  }
  return made;
}

}  // namespace mcslam
