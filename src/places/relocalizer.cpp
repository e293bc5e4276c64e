#include "mcslam/places/relocalizer.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <climits>
#include <cmath>

#include <spdlog/spdlog.h>

namespace mcslam {

Vec6 verifiedPoseSigma(const RelocalizationResult& result, const PlacesOptions& options) {
  Vec6 s;
  const Eigen::FullPivLU<Mat6> lu(result.information);
  const Vec6 variance = lu.isInvertible() ? Vec6(lu.inverse().diagonal()) : Vec6::Constant(1e6);
  for (int k = 0; k < 6; ++k) s[k] = std::sqrt(std::max(variance[k], 0.0));
  s.head<3>() = s.head<3>().cwiseMax(options.loop_sigma_translation);
  s.tail<3>() = s.tail<3>().cwiseMax(options.loop_sigma_rotation_deg * M_PI / 180.0);
  return s;
}

bool withinUncertainty(const SE3& correction, const Vec6& sigma) {
  return correction.log().cwiseQuotient(sigma).squaredNorm() < 12.59;
}

bool sameCorrection(const SE3& a, const SE3& b, double distance) {
  const SE3 difference = a.inverse() * b;
  return difference.t.norm() < 0.05 * std::max(1.0, distance) && so3Log(difference.R).norm() < 2.0 * M_PI / 180.0;
}

namespace {

// A RANSAC consensus only proposes a pose: the guided search and min_inliers decide.
constexpr int kRansacMinInliers = 12;
// ... and a consensus of under a fifth of the putative matches is not even a proposal: chance agreement among
// descriptor matches (BENCHMARKS.md, "Kidnap").
constexpr double kRansacMinShare = 0.2;
constexpr int kGridCell = 32;
constexpr double kSearchRadiusPx = 8.0;  // at octave 0, around the projection (ORB-SLAM's relocalization: 10)
// A consensus of distant points alone (a far wall) trades a few degrees of pitch or yaw for metres of translation
// almost freely; nearer points then project tens of pixels from their keypoints, and a narrow search there finds
// texture that confirms the wrong pose. So the first guided pass searches this wide and keeps only distinctive
// matches (ratio test): a pose refined on them is close enough for the narrow pass.
constexpr double kWideSearchRadiusPx = 4 * kSearchRadiusPx;

AbsolutePoseRansacOptions ransacOptions() {
  AbsolutePoseRansacOptions r;
  r.max_iterations = 300;
  r.min_inliers = kRansacMinInliers;
  r.seed = 7;
  return r;
}

}  // namespace

Relocalizer::Relocalizer(const Rig& rig, const PlacesOptions& options, float scale_factor, int max_features_per_camera)
    : rig_(rig),
      options_(options),
      octave_sigma_(scale_factor),
      candidates_(static_cast<std::size_t>(options.max_candidates)),
      group_(static_cast<std::size_t>(2 * options.neighbour_keyframes + 1)),
      matches_(static_cast<std::size_t>(rig.size() * max_features_per_camera)),
      observations_(matches_.size()),
      inliers_(matches_.size()),
      ransac_(rig, rig.size() * max_features_per_camera, ransacOptions()),
      refiner_(rig, rig.size() * max_features_per_camera) {
  const auto per_camera = static_cast<std::size_t>(max_features_per_camera);
  for (int c = 0; c < rig.size(); ++c) {
    grids_.emplace_back(rig.model(c).width(), rig.model(c).height(), kGridCell, max_features_per_camera);
    best_distance_.emplace_back(per_camera, 0);
    best_point_.emplace_back(per_camera, nullptr);
    best_keyframe_.emplace_back(per_camera, -1);
  }
}

void Relocalizer::prepareFrame(const FrameFeatures& frame) {
  for (int c = 0; c < frame.cameras(); ++c)
    if (frame.present[static_cast<std::size_t>(c)])
      grids_[static_cast<std::size_t>(c)].build(frame.sets[static_cast<std::size_t>(c)]);
}

int Relocalizer::searchByProjection(const FrameFeatures& frame, const PlaceMap& map, const SE3& T_w_b, double radius_px,
                                    float ratio) {
  const int cams = frame.cameras();
  for (int c = 0; c < cams; ++c)
    std::fill_n(best_point_[static_cast<std::size_t>(c)].begin(), frame.sets[static_cast<std::size_t>(c)].count,
                nullptr);
  for (int c = 0; c < cams; ++c) {
    if (!frame.present[static_cast<std::size_t>(c)]) continue;
    const SE3 T_c_w = (T_w_b * rig_.T_b_c(c)).inverse();
    const CameraModel& model = rig_.model(c);
    const FeatureSet& set = frame.sets[static_cast<std::size_t>(c)];
    auto& best_distance = best_distance_[static_cast<std::size_t>(c)];
    auto& best_point = best_point_[static_cast<std::size_t>(c)];
    auto& best_keyframe = best_keyframe_[static_cast<std::size_t>(c)];
    const auto offer = [&](int index, int distance, const PlacePoint& p, int kf) {
      const auto k = static_cast<std::size_t>(index);
      if (distance > options_.max_hamming || (best_point[k] && distance >= best_distance[k])) return;
      best_point[k] = &p;
      best_distance[k] = distance;
      best_keyframe[k] = kf;
    };
    for (int g = 0; g < group_count_; ++g) {
      const int kf = group_[static_cast<std::size_t>(g)];
      const SE3 T_c_k = T_c_w * map.keyframe(kf).T_w_k;
      for (const PlacePoint& p : map.points(kf)) {
        const Vec3 p_c = T_c_k * p.p_k.cast<double>();
        Vec2 uv;
        if (p_c.z() <= 0 || !model.project(p_c, uv) || !model.inImage(uv, 0)) continue;
        const double radius = radius_px * octave_sigma_[p.octave];
        int first = INT_MAX, second = INT_MAX, first_index = -1;
        grids_[static_cast<std::size_t>(c)].forEachNear(uv.x(), uv.y(), radius, [&](const KeypointGrid::Entry& e) {
          if ((Vec2(e.x, e.y) - uv).squaredNorm() > radius * radius) return;
          const int d = hammingDistance(p.descriptor, set.descriptors[static_cast<std::size_t>(e.index)]);
          if (ratio <= 0) {
            offer(e.index, d, p, kf);
          } else if (d < first) {
            second = first;
            first = d;
            first_index = e.index;
          } else if (d < second) {
            second = d;
          }
        });
        if (first_index >= 0 && passesRatioTest(first, second, ratio)) offer(first_index, first, p, kf);
      }
    }
  }
  int count = 0;
  for (int c = 0; c < cams; ++c) {
    if (!frame.present[static_cast<std::size_t>(c)]) continue;
    const FeatureSet& set = frame.sets[static_cast<std::size_t>(c)];
    for (int k = 0; k < set.count; ++k) {
      const PlacePoint* p = best_point_[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)];
      if (!p || !frame.valid[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)]) continue;
      const int kf = best_keyframe_[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)];
      addMatch(frame, map, c, k, p, kf, count);
    }
  }
  return count;
}

void Relocalizer::addMatch(const FrameFeatures& frame, const PlaceMap& map, int c, int k, const PlacePoint* point,
                           int keyframe, int& count) {
  const Keypoint& kp = frame.sets[static_cast<std::size_t>(c)].keypoints[static_cast<std::size_t>(k)];
  const Vec3 p_w = map.keyframe(keyframe).T_w_k * point->p_k.cast<double>();
  matches_[static_cast<std::size_t>(count)] = {static_cast<int16_t>(c), k, p_w, point, keyframe};
  observations_[static_cast<std::size_t>(count)] = makePoseObservation(
      rig_, c, Vec2(kp.x, kp.y), frame.bearings[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)], p_w,
      octave_sigma_[kp.octave]);
  ++count;
}

void Relocalizer::setRig(const Rig& rig) {
  for (int c = 0; c < rig.size(); ++c) {
    rig_.cameras[static_cast<std::size_t>(c)].T_b_c = rig.T_b_c(c);
    ransac_.setExtrinsic(c, rig.T_b_c(c));
    refiner_.setExtrinsic(c, rig.T_b_c(c));
  }
}

int Relocalizer::gatherGroup(const PlaceMap& map, int keyframe) {
  group_count_ = 0;
  group_[static_cast<std::size_t>(group_count_++)] = keyframe;
  int before = map.keyframe(keyframe).previous, after = map.keyframe(keyframe).next;
  for (int i = 0; i < options_.neighbour_keyframes; ++i) {
    if (before >= 0) {
      group_[static_cast<std::size_t>(group_count_++)] = before;
      before = map.keyframe(before).previous;
    }
    if (after >= 0) {
      group_[static_cast<std::size_t>(group_count_++)] = after;
      after = map.keyframe(after).next;
    }
  }
  return group_count_;
}

int Relocalizer::match(const FrameFeatures& frame, const FrameWords& words, const PlaceMap& map) {
  int count = 0;
  for (int c = 0; c < frame.cameras(); ++c) {
    if (!frame.present[static_cast<std::size_t>(c)]) continue;
    const FeatureSet& set = frame.sets[static_cast<std::size_t>(c)];
    for (int k = 0; k < set.count; ++k) {
      if (!frame.valid[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)]) continue;
      const Descriptor& d = set.descriptors[static_cast<std::size_t>(k)];
      const int32_t node = words.node(c, k);
      int best = INT_MAX, second = INT_MAX, best_keyframe = -1;
      const PlacePoint* best_point = nullptr;
      for (int g = 0; g < group_count_; ++g) {
        for (const PlacePoint& p : map.pointsOfNode(group_[static_cast<std::size_t>(g)], node)) {
          const int distance = hammingDistance(d, p.descriptor);
          if (best_point && p.landmark_id == best_point->landmark_id) {
            best = std::min(best, distance);  // the same landmark in another keyframe: no rival
            continue;
          }
          if (distance < best) {
            second = best;
            best = distance;
            best_point = &p;
            best_keyframe = group_[static_cast<std::size_t>(g)];
          } else if (distance < second) {
            second = distance;
          }
        }
      }
      if (!best_point || best > options_.max_hamming || !passesRatioTest(best, second, options_.match_ratio)) continue;
      addMatch(frame, map, c, k, best_point, best_keyframe, count);
    }
  }
  return count;
}

PoseRefinementResult Relocalizer::poseByProjection(const FrameFeatures& frame, const PlaceMap& map, int keyframe,
                                                   const SE3& hypothesis) {
  prepareFrame(frame);
  gatherGroup(map, keyframe);
  int projected = 0;
  return refineByProjection(frame, map, hypothesis, projected);
}

PoseRefinementResult Relocalizer::refineByProjection(const FrameFeatures& frame, const PlaceMap& map,
                                                     const SE3& hypothesis, int& projected) {
  SE3 start = hypothesis;
  const int distinctive = searchByProjection(frame, map, hypothesis, kWideSearchRadiusPx, options_.match_ratio);
  const PoseRefinementResult coarse = refiner_.refine(
      std::span<const PoseObservation>(observations_.data(), static_cast<std::size_t>(distinctive)), hypothesis);
  if (coarse.success && coarse.num_inliers >= kRansacMinInliers) start = coarse.T_w_b;
  projected = searchByProjection(frame, map, start, kSearchRadiusPx, 0.0f);
  return refiner_.refine(std::span<const PoseObservation>(observations_.data(), static_cast<std::size_t>(projected)),
                         start);
}

bool Relocalizer::verify(const FrameFeatures& frame, const FrameWords& words, const PlaceMap& map, int keyframe,
                         RelocalizationResult& result) {
  gatherGroup(map, keyframe);
  const int matched = match(frame, words, map);
  if (matched < kRansacMinInliers) return false;
  const AbsolutePoseRansacResult r =
      ransac_.estimate(std::span<const PoseObservation>(observations_.data(), static_cast<std::size_t>(matched)));
  if (!r.ok() || r.num_inliers < kRansacMinShare * matched) return false;
  // The consensus may be repeated texture: the pose must find its points where they project.
  int projected = 0;
  const PoseRefinementResult refined = refineByProjection(frame, map, r.T_w_b, projected);
  spdlog::debug("relocalizer: keyframe {} (group {}): {} matches, {} RANSAC inliers, {} by projection, {} inliers",
                map.keyframe(keyframe).id, group_count_, matched, r.num_inliers, projected, refined.num_inliers);
  // A right pose explains most of what it projects onto similar keypoints, and a good part of the frame; a pose
  // aliased by repeated texture only the aliased part (ORB-SLAM asks 50 inliers of 1000 features: the same share of
  // the whole rig's keypoints here).
  const double inliers = refined.num_inliers;
  if (!refined.success || refined.num_inliers < options_.min_inliers ||
      inliers < options_.min_inlier_share * static_cast<double>(projected) ||
      inliers < options_.min_frame_share * static_cast<double>(frame.keypointCount()))
    return false;
  inlier_count_ = 0;
  for (int i = 0; i < projected; ++i)
    if (refined.inlier_mask[static_cast<std::size_t>(i)])
      inliers_[static_cast<std::size_t>(inlier_count_++)] = matches_[static_cast<std::size_t>(i)];
  result.ok = true;
  result.T_w_b = refined.T_w_b;
  result.keyframe = keyframe;
  result.inliers = refined.num_inliers;
  result.information = refined.information;
  return true;
}

}  // namespace mcslam
