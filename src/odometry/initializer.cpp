#include "mcslam/odometry/initializer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mcslam {

Initializer::Initializer(const Rig& rig, const OdometryOptions& options, int max_features_per_camera)
    : rig_(rig), options_(options), estimator_(rig.size() * max_features_per_camera, rig.size()) {
  reference_.allocate(rig.size(), max_features_per_camera);
  correspondences_.reserve(static_cast<std::size_t>(rig.size()) * max_features_per_camera);
  // As many as correspondences_ (one camera's share cannot exceed them): no allocation whatever the split.
  camera_matches_.reserve(correspondences_.capacity());
  best_camera_.inlier_mask.reserve(correspondences_.capacity());
  best_of_ref_.resize(max_features_per_camera);
  best_ref_distance_.resize(max_features_per_camera);
  candidate_of_cur_.resize(max_features_per_camera);
}

namespace {

bool usable(const MultiViewFeature& mv, double max_depth_sigma) {
  return mv.has_point && mv.relative_depth_sigma <= max_depth_sigma;
}

}  // namespace

int Initializer::usableMultiView(const FrameFeatures& f, double max_depth_sigma) {
  int n = 0;
  for (int t = 0; t < f.mv_count; ++t) n += usable(f.mv[t], max_depth_sigma) ? 1 : 0;
  return n;
}

double Initializer::multiViewDisparityPx(const FrameFeatures& f, int t, const Rig& rig) {
  const MultiViewFeature& mv = f.mv[t];
  double widest = 0;
  for (int a = 0; a < mv.size; ++a) {
    const int ca = f.mv_refs[mv.first + a].cam;
    const Vec3 ray_a = (mv.p_b - rig.T_b_c(ca).t).normalized();
    for (int b = a + 1; b < mv.size; ++b) {
      const int cb = f.mv_refs[mv.first + b].cam;
      const Vec3 ray_b = (mv.p_b - rig.T_b_c(cb).t).normalized();
      const double focal = 0.5 * (rig.model(ca).fx() + rig.model(cb).fx());
      widest = std::max(widest, std::acos(std::clamp(ray_a.dot(ray_b), -1.0, 1.0)) * focal);
    }
  }
  return widest;
}

int Initializer::metricMultiView(const FrameFeatures& f, const Rig& rig, double max_depth_sigma,
                                 double min_disparity_px) {
  int n = 0;
  for (int t = 0; t < f.mv_count; ++t)
    n += usable(f.mv[t], max_depth_sigma) && multiViewDisparityPx(f, t, rig) >= min_disparity_px ? 1 : 0;
  return n;
}

// Mutual nearest neighbours by descriptor between the reference and the frame, camera by camera,
// with a ratio test. No geometric prior: the rig may have turned a lot since the reference.
int Initializer::matchToReference(const FrameFeatures& f) {
  correspondences_.clear();
  constexpr int kMaxHamming = 60;
  constexpr float kRatio = 0.8f;
  for (int c = 0; c < f.cameras(); ++c) {
    if (!f.present[c] || !reference_.present[c]) continue;
    const FeatureSet& ref = reference_.sets[c];
    const FeatureSet& cur = f.sets[c];
    // Each distance is computed once: it updates both the current keypoint's best and second best and the
    // reference keypoint's best (first smallest wins in both directions).
    std::fill(best_of_ref_.begin(), best_of_ref_.begin() + ref.count, -1);
    std::fill(best_ref_distance_.begin(), best_ref_distance_.begin() + ref.count, 257);
    for (int k = 0; k < cur.count; ++k) {
      int best = 257, second = 257, best_r = -1;
      for (int r = 0; r < ref.count; ++r) {
        const int d = hammingDistance(cur.descriptors[k], ref.descriptors[r]);
        if (d < best_ref_distance_[r]) {
          best_ref_distance_[r] = d;
          best_of_ref_[r] = k;
        }
        if (d < best) {
          second = best;
          best = d;
          best_r = r;
        } else if (d < second) {
          second = d;
        }
      }
      const bool passes = f.valid[c][k] && best_r >= 0 && best <= kMaxHamming && passesRatioTest(best, second, kRatio);
      candidate_of_cur_[k] = passes ? best_r : -1;
    }
    for (int k = 0; k < cur.count; ++k) {
      const int best_r = candidate_of_cur_[k];
      if (best_r < 0 || best_of_ref_[best_r] != k || !reference_.valid[c][best_r]) continue;
      RelativeCorrespondence m;
      m.camera1 = c;
      m.bearing1 = reference_.bearings[c][best_r];
      m.camera2 = c;
      m.bearing2 = f.bearings[c][k];
      correspondences_.push_back(m);
    }
  }
  return static_cast<int>(correspondences_.size());
}

RelativePoseOptions Initializer::relativePoseOptions(uint64_t frame_index) const {
  RelativePoseOptions ro;
  ro.seed = 1 + frame_index;
  const double f_mean = 0.5 * (rig_.rig().model(0).fx() + rig_.rig().model(0).fy());
  ro.bearing_sigma_rad = 0.7 / f_mean;  // keypoints at the finest octave: ~0.7 px; inliers within 3 sigma
  ro.min_inliers = std::max(20, options_.init_min_matches / 2);
  return ro;
}

Initializer::TwoFrame Initializer::feed(const FrameFeatures& f, uint64_t frame_index, SE3& T_ref_cur) {
  if (!has_reference_) {
    reference_ = f;
    reference_index_ = frame_index;
    has_reference_ = true;
    last_status_ = RelativePoseStatus::TooFewCorrespondences;
    return TwoFrame::Waiting;
  }
  last_matches_ = matchToReference(f);
  const bool too_old = frame_index - reference_index_ > static_cast<uint64_t>(options_.init_max_reference_age);
  if (last_matches_ < options_.init_min_matches) {
    // The view changed too much for this reference: start again from this frame.
    if (too_old || last_matches_ < options_.init_min_matches / 2) {
      reference_ = f;
      reference_index_ = frame_index;
    }
    last_status_ = RelativePoseStatus::TooFewCorrespondences;
    return TwoFrame::Waiting;
  }
  if (rig_.cameras() > 1 && f.mv_count == 0 && reference_.mv_count == 0) {
    last_metric_ = false;
    const RelativePoseResult& r = upToScale(frame_index, T_ref_cur);
    last_status_ = r.status;
    return r.ok() ? TwoFrame::Ready : TwoFrame::Waiting;
  }
  last_metric_ = rig_.cameras() > 1;
  const RelativePoseOptions ro = relativePoseOptions(frame_index);
  const RelativePoseResult& r = rig_.cameras() == 1 ? estimator_.central(correspondences_, ro)
                                                    : estimator_.generalized(rig_.rig(), correspondences_, ro);
  last_status_ = r.status;
  if (!r.ok()) return TwoFrame::Waiting;
  if (rig_.cameras() == 1) {
    // The central solver works in camera frames: bring the motion into the body frame.
    const SE3& T_b_c = rig_.T_b_c(0);
    T_ref_cur = T_b_c * r.T_1_2 * T_b_c.inverse();
  } else {
    T_ref_cur = r.T_1_2;
  }
  return TwoFrame::Ready;
}

const RelativePoseResult& Initializer::upToScale(uint64_t frame_index, SE3& T_ref_cur) {
  const RelativePoseOptions ro = relativePoseOptions(frame_index);
  RelativePoseResult& best = best_camera_;
  int best_cam = -1;
  for (int c = 0; c < rig_.cameras(); ++c) {
    camera_matches_.clear();
    for (const RelativeCorrespondence& m : correspondences_) {
      if (m.camera1 == c) camera_matches_.push_back(m);
    }
    if (static_cast<int>(camera_matches_.size()) < ro.min_inliers) continue;
    const RelativePoseResult& r = estimator_.central(camera_matches_, ro);
    // A camera with a sound pose beats one without; then the most inliers.
    const bool better =
        best_cam < 0 || (r.ok() && !best.ok()) || (r.ok() == best.ok() && r.num_inliers > best.num_inliers);
    if (better) {
      best = r;  // within the capacity reserved: no allocation
      best_cam = c;
    }
  }
  if (best_cam < 0) {
    best.status = RelativePoseStatus::TooFewCorrespondences;
    return best;
  }
  if (best.ok()) {
    // The camera's unit translation becomes the body's motion: the map's unit is arbitrary until the window's
    // turns fix it.
    const SE3& T_b_c = rig_.T_b_c(best_cam);
    T_ref_cur = T_b_c * best.T_1_2 * T_b_c.inverse();
  }
  return best;
}

}  // namespace mcslam
