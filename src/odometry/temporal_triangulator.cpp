#include "mcslam/odometry/temporal_triangulator.hpp"

#include <algorithm>
#include <cmath>

#include "mcslam/core/median.hpp"

namespace mcslam {

namespace {

constexpr int kMaxPrevious = 16;
constexpr int kMaxHamming = 50;  // stricter than tracking: nothing else vouches for these matches
constexpr float kRatio = 0.75f;
constexpr double kEpipolarPx = 2.0;
constexpr int kMaxOctaveDifference = 2;

}  // namespace

TemporalTriangulator::TemporalTriangulator(const Rig& rig, const OdometryOptions& options, int max_features_per_camera)
    : options_(options),
      capacity_(max_features_per_camera),
      min_depth_(std::max(0.05, options.new_points.min_depth)),
      band_index_(max_features_per_camera, options.levels) {
  const int cams = rig.size();
  for (const RigCamera& c : rig.cameras) half_fov_.push_back(c.model.imageHalfAngle());
  candidates_.resize(static_cast<std::size_t>(cams) * max_features_per_camera);
  claim_.resize(static_cast<std::size_t>(cams) * max_features_per_camera);
  best_.resize(max_features_per_camera);
  inverse_ranges_.resize(static_cast<std::size_t>(cams) * max_features_per_camera);
  gate_.resize(std::max(options.levels, 1));
  const int max_obs = 2 * cams;
  tri_obs_.resize(max_obs);
  tri_refs_.resize(max_obs);
  tri_kf_.resize(max_obs);
  created_.resize(static_cast<std::size_t>(cams) * max_features_per_camera);  // one per keypoint of the new keyframe
}

int TemporalTriangulator::previousKeyframes(const Map& map, int slot, int* previous) const {
  const Keyframe& kn = map.keyframe(slot);
  int np = 0;
  for (int want = 0; want < std::min(options_.temporal_keyframes, kMaxPrevious); ++want) {
    int best = -1;
    for (int i = 0; i < map.keyframeCapacity(); ++i) {
      const Keyframe& k = map.keyframe(i);
      if (!k.alive || k.id >= kn.id) continue;
      bool taken = false;
      for (int j = 0; j < np; ++j) taken = taken || previous[j] == i;
      if (!taken && (best < 0 || k.id > map.keyframe(best).id)) best = i;
    }
    if (best < 0) break;
    previous[np++] = best;
  }
  return np;
}

int TemporalTriangulator::triangulate(Map& map, const Rig& rig, int slot) {
  created_count_ = 0;
  map_full_ = false;
  int previous[kMaxPrevious];
  const int np = previousKeyframes(map, slot, previous);
  // Where the map's unit rests on these points (scene_referenced_points_), they are judged by the uncertainty of
  // their inverse depth against the scene's, not of their depth against their own, and without a parallax bound
  // (TriangulationOptions::reference_inverse_depth): both favour the points that noise put nearer, and a map whose
  // unit rests on them shrinks at every corner. Where multi-view features give every frame its metres, the own
  // bounds stay: they reject points whose depth is imprecise, which tracking takes as exact. A keyframe without a
  // scene yet (initialization) uses the own bounds too.
  //
  // Where the map's unit rests on these points, keypoints that already have a landmark take part in the ratio
  // test too (and are never chosen): without them a lookalike on the epipolar line stands unopposed whenever the
  // true partner has a landmark, and the scale estimates then agree with the wrong unit those pairs give the map.
  // docs/design/odometry.md has the figures.
  landmarks_compete_ = scene_referenced_points_;
  TriangulationOptions tri_options = options_.new_points;
  if (scene_referenced_points_) tri_options.reference_inverse_depth = sceneInverseDepth(map, rig, slot);
  if (tri_options.reference_inverse_depth > 0) tri_options.min_parallax_deg = 0;

  for (int pi = 0; pi < np; ++pi) {
    const int nc = matchKeyframes(rig, map.keyframe(slot), map.keyframe(previous[pi]));
    if (!triangulateCandidates(map, rig, slot, previous[pi], nc, tri_options)) {
      map_full_ = true;
      break;
    }
  }
  return created_count_;
}

int TemporalTriangulator::matchKeyframes(const Rig& rig, const Keyframe& kn, const Keyframe& ko) {
  const int cams = rig.size();
  int nc = 0;
  for (int c = 0; c < cams; ++c)
    std::fill(claim_.begin() + c * capacity_, claim_.begin() + c * capacity_ + ko.features.sets[c].count, -1);

  for (int c2 = 0; c2 < cams; ++c2) {
    if (!kn.features.present[c2]) continue;
    const SE3 T_w_c2 = kn.T_w_b * rig.T_b_c(c2);
    const FeatureSet& set2 = kn.features.sets[c2];
    std::fill(best_.begin(), best_.begin() + set2.count, Best{});
    for (int c1 = 0; c1 < cams; ++c1) {
      if (ko.features.present[c1]) matchCameras(rig, kn, c2, T_w_c2, ko, c1);
    }
    for (int a = 0; a < set2.count; ++a) {
      const Best& best = best_[a];
      if (best.kp < 0 || !best.free || best.distance > kMaxHamming ||
          !passesRatioTest(best.distance, best.second, kRatio)) {
        continue;
      }
      // One candidate per old keypoint: the closest descriptor wins.
      int32_t& claim = claim_[static_cast<std::size_t>(best.cam) * capacity_ + best.kp];
      if (claim >= 0) {
        if (candidates_[claim].distance <= best.distance) continue;
        candidates_[claim].distance = -1;  // beaten
      }
      claim = nc;
      candidates_[nc++] = Candidate{static_cast<int16_t>(c2), static_cast<int16_t>(best.cam), a, best.kp,
                                    static_cast<int16_t>(best.distance)};
    }
  }
  return nc;
}

void TemporalTriangulator::matchCameras(const Rig& rig, const Keyframe& kn, int c2, const SE3& T_w_c2,
                                        const Keyframe& ko, int c1) {
  const SE3 T_w_c1 = ko.T_w_b * rig.T_b_c(c1);
  const double axes = std::acos(std::clamp(T_w_c1.R.col(2).dot(T_w_c2.R.col(2)), -1.0, 1.0));
  if (axes > half_fov_[c1] + half_fov_[c2]) return;  // the two views cannot share a point
  const Vec3 baseline = T_w_c2.t - T_w_c1.t;
  if (!band_index_.begin(baseline)) return;  // no baseline: no depth from this pair
  const FeatureSet& set1 = ko.features.sets[c1];
  for (int b = 0; b < set1.count; ++b) {
    if ((!landmarks_compete_ && ko.landmark_of[c1][b] >= 0) || !ko.features.valid[c1][b]) continue;
    band_index_.add(b, T_w_c1.R * ko.features.bearings[c1][b], set1.keypoints[b].octave);
  }
  band_index_.finish();
  const CameraModel& m1 = rig.model(c1);
  const double f1 = 0.5 * (m1.fx() + m1.fy());
  for (int o = 0; o < options_.levels; ++o) gate_[o] = kEpipolarPx * octave_scale_[o] / f1;

  const FeatureSet& set2 = kn.features.sets[c2];
  for (int a = 0; a < set2.count; ++a) {
    if (kn.landmark_of[c2][a] >= 0 || !kn.features.valid[c2][a]) continue;
    const Vec3 d2 = T_w_c2.R * kn.features.bearings[c2][a];
    const int oa = set2.keypoints[a].octave;
    band_index_.forEachOnPlane(d2, oa - kMaxOctaveDifference, oa + kMaxOctaveDifference, gate_.data(),
                               [&](int32_t b, const float* d1f) {
                                 consider(kn, c2, a, d2, ko, c1, b, Vec3(d1f[0], d1f[1], d1f[2]), baseline);
                               });
  }
}

void TemporalTriangulator::consider(const Keyframe& kn, int c2, int a, const Vec3& d2, const Keyframe& ko, int c1,
                                    int32_t b, const Vec3& d1, const Vec3& baseline) {
  // The two rays must meet in front of both cameras, at least the minimum depth along the new one.
  const double cosine = d2.dot(d1);
  const double den = 1.0 - cosine * cosine;
  if (den > 1e-12) {
    const double along2 = d2.dot(baseline), along1 = d1.dot(baseline);
    const double t2 = (cosine * along1 - along2) / den;
    const double t1 = (along1 - cosine * along2) / den;
    if (t2 < min_depth_ || t1 <= 0) return;
  }
  const int d = hammingDistance(kn.features.sets[c2].descriptors[a], ko.features.sets[c1].descriptors[b]);
  Best& best = best_[a];
  if (d < best.distance) {
    best.second = best.distance;
    best.distance = d;
    best.cam = c1;
    best.kp = b;
    best.free = ko.landmark_of[c1][b] < 0;
  } else if (d < best.second) {
    best.second = d;
  }
}

bool TemporalTriangulator::triangulateCandidates(Map& map, const Rig& rig, int slot, int po, int nc,
                                                 const TriangulationOptions& tri) {
  const Keyframe& kn = map.keyframe(slot);
  for (int i = 0; i < nc; ++i) {
    const Candidate& cand = candidates_[i];
    if (cand.distance < 0 || kn.landmark_of[cand.cam_new][cand.kp_new] >= 0) continue;
    int n = 0;
    addRays(map, rig, slot, cand.cam_new, cand.kp_new, n);
    addRays(map, rig, po, cand.cam_old, cand.kp_old, n);
    const TriangulationResult result = mcslam::triangulate(tri_obs_.data(), n, tri);
    if (!result.ok()) continue;
    const int lm = map.createLandmark(result.point, kn.features.sets[cand.cam_new].descriptors[cand.kp_new], kn.id);
    if (lm < 0) return false;
    for (int r = 0; r < n; ++r) map.addObservation(lm, tri_kf_[r], tri_refs_[r].cam, tri_refs_[r].index);
    created_[created_count_++] = lm;
  }
  return true;
}

void TemporalTriangulator::addRays(const Map& map, const Rig& rig, int kf_slot, int cam, int kp, int& n) {
  const Keyframe& k = map.keyframe(kf_slot);
  const int mv = k.features.mv_of[cam][kp];
  const int first = mv < 0 ? 0 : k.features.mv[mv].first;
  const int size = mv < 0 ? 1 : k.features.mv[mv].size;
  for (int r = 0; r < size; ++r) {
    const int c = mv < 0 ? cam : k.features.mv_refs[first + r].cam;
    const int idx = mv < 0 ? kp : k.features.mv_refs[first + r].index;
    if (n >= static_cast<int>(tri_obs_.size()) || k.landmark_of[c][idx] >= 0) continue;
    TriangulationObservation& o = tri_obs_[n];
    const Keypoint& key = k.features.sets[c].keypoints[idx];
    o.model = &rig.model(c);
    o.T_f_c = k.T_w_b * rig.T_b_c(c);
    o.uv = Vec2(key.x, key.y);
    o.bearing = k.features.bearings[c][idx];
    o.sigma_px = octave_scale_[key.octave];
    tri_refs_[n] = KeypointRef{static_cast<int16_t>(c), idx};
    tri_kf_[n] = kf_slot;
    ++n;
  }
}

double TemporalTriangulator::sceneInverseDepth(const Map& map, const Rig& rig, int slot) {
  constexpr int kMinLandmarks = 20;  // a median worth the name
  const Keyframe& k = map.keyframe(slot);
  int n = 0;
  for (int c = 0; c < k.features.cameras(); ++c) {
    const Vec3 centre = k.T_w_b * rig.T_b_c(c).t;
    for (int i = 0; i < k.features.sets[c].count; ++i) {
      const int lm = k.landmark_of[c][i];
      if (lm < 0) continue;
      const double range = (map.landmark(lm).p_w - centre).norm();
      if (range > 0) inverse_ranges_[n++] = 1.0 / range;
    }
  }
  return n < kMinLandmarks ? 0.0 : medianOf(inverse_ranges_, n);
}

}  // namespace mcslam
