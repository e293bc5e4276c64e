#include "mcslam/odometry/local_mapper.hpp"

#include "backend_worker.hpp"
#include "median.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mcslam {

namespace {


// Exact bounds: every keypoint of a window keyframe observes at most one landmark.
backend::WindowCapacity windowCapacity(const OdometryOptions& o, const Map& map, int cameras, int features_per_camera) {
  backend::WindowCapacity cap;
  cap.max_keyframes = o.window_keyframes;
  cap.max_observations = (o.window_keyframes + 1) * cameras * features_per_camera;  // +1: the keyframe being added
  cap.max_landmarks = std::min(map.landmarkCapacity(), cap.max_observations);
  return cap;
}

// Oldest keyframes the back-end holds: two when the map's scale is not the window's to change (one camera has no
// metric scale; a remembered scale is held), else one.
int gaugeFixedOldest(bool monocular, bool hold_scale) { return monocular || hold_scale ? 2 : 1; }

backend::SolverOptions solverOptions(const OdometryOptions& o, bool monocular) {
  backend::SolverOptions so;
  so.refine_extrinsics = o.refine_extrinsics;
  so.extrinsic_prior.translation = o.extrinsic_sigma_translation;
  so.extrinsic_prior.rotation = o.extrinsic_sigma_rotation_deg * M_PI / 180.0;
  so.gauge_fixed_oldest = gaugeFixedOldest(monocular, false);
  return so;
}

}  // namespace

LocalMapper::LocalMapper(const Rig& rig, const OdometryOptions& options, Map& map, int max_features_per_camera)
    : rig_state_(rig),
      calibration_(rig),
      options_(options),
      map_(map),
      band_index_(max_features_per_camera, options.levels),
      capacity_(max_features_per_camera),
      monocular_(rig.size() == 1) {
  const int cams = rig.size();
  calibration_dropped_.assign(cams, 0);
  touched_.resize(map.landmarkCapacity());
  touched_flag_.assign(map.landmarkCapacity(), 0);
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
  outliers_.resize(static_cast<std::size_t>(cams) * max_features_per_camera * options.window_keyframes);
  if (options.backend) {
    solver_ = std::make_unique<backend::SlidingWindowSolver>(rig, windowCapacity(options, map, rig.size(), max_features_per_camera), solverOptions(options, monocular_));
    if (options.backend_thread) worker_ = std::make_unique<BackendWorker>();
  }
}

LocalMapper::~LocalMapper() {
  if (worker_) worker_->wait();  // the solver must outlive a solve in flight
}

void LocalMapper::reset() {
  if (worker_) worker_->wait();
  solving_ = false;  // the window is dropped with the map: its last result does not matter
  if (solver_) {
    // A fresh window (the old one's keyframes and landmarks are gone with the map), on the same prior, starting
    // from the current extrinsics. This allocates: it happens only when tracking was lost, never per frame.
    solver_.reset();
    solver_ = std::make_unique<backend::SlidingWindowSolver>(calibration_, windowCapacity(options_, map_, rig_state_.cameras(), capacity_),
                                                             solverOptions(options_, monocular_));
    for (int c = 0; c < rig_state_.cameras(); ++c) {  // refused where not refined
      solver_->setExtrinsic(c, rig_state_.T_b_c(c), !calibration_dropped_[c]);
    }
  }
  std::fill(touched_flag_.begin(), touched_flag_.end(), 0);
  touched_count_ = 0;
}

void LocalMapper::rescale(double s, const Vec3& center) {
  for (int i = 0; i < map_.keyframeCapacity(); ++i) {
    Keyframe& k = map_.keyframe(i);
    if (!k.alive) continue;
    k.T_w_b.t = center + s * (k.T_w_b.t - center);
    if (solver_ && k.in_backend) solver_->setKeyframePose(k.id, k.T_w_b);
  }
  for (int lm = 0; lm < map_.landmarkCapacity(); ++lm) {
    Landmark& l = map_.landmark(lm);
    if (!l.alive) continue;
    l.p_w = center + s * (l.p_w - center);
    if (solver_ && l.in_backend) solver_->setLandmarkPosition(lm, l.p_w);
    // ORB finds it again over distances that scale with it.
    l.min_distance *= static_cast<float>(s);
    l.max_distance *= static_cast<float>(s);
  }
}

void LocalMapper::holdScale(bool hold) {
  if (!solver_) return;
  const bool by_window = hold && options_.hold_window_scale;
  solver_->setHoldWindowScale(by_window);
  solver_->setGaugeFixedOldest(by_window ? 1 : gaugeFixedOldest(monocular_, hold));
}

Rig LocalMapper::refinedRig() const {
  if (worker_) worker_->wait();
  return solver_ ? solver_->refinedRig() : rig_state_.rig();
}

void LocalMapper::adoptSolvedExtrinsics() {
  if (!solver_) return;
  for (int c = 0; c < rig_state_.cameras(); ++c) rig_state_.setExtrinsic(c, solver_->extrinsic(c));
}

void LocalMapper::reestimateExtrinsic(int cam, const SE3& T_b_c) {
  rig_state_.setExtrinsic(cam, T_b_c);
  rig_state_.markReestimated(cam);
  if (!solver_ || solving_ || solver_->setExtrinsic(cam, T_b_c) != backend::Status::Ok) return;
  calibration_dropped_[cam] = 1;
}

int LocalMapper::keyframeSlotOfId(int64_t id) const {
  for (int i = 0; i < map_.keyframeCapacity(); ++i) {
    if (map_.keyframe(i).alive && map_.keyframe(i).id == id) return i;
  }
  return -1;
}

void LocalMapper::touch(int lm) {
  if (touched_flag_[lm]) return;
  touched_flag_[lm] = 1;
  touched_[touched_count_++] = lm;
}

void LocalMapper::finishTouched() {
  for (int i = 0; i < touched_count_; ++i) {
    const int lm = touched_[i];
    touched_flag_[lm] = 0;
    if (map_.landmark(lm).alive) map_.updateLandmarkAppearance(lm, rig_state_.rig(), options_.scale_factor, options_.levels);
  }
  touched_count_ = 0;
}

int LocalMapper::allocateKeyframe() {
  int slot = map_.createKeyframe();
  if (slot >= 0) return slot;
  // The pool is full: drop the oldest keyframe that has left the back-end window.
  int victim = -1;
  for (int i = 0; i < map_.keyframeCapacity(); ++i) {
    const Keyframe& k = map_.keyframe(i);
    if (k.alive && !k.in_backend && (victim < 0 || k.id < map_.keyframe(victim).id)) victim = i;
  }
  if (victim < 0) return -1;
  // Its landmarks lose their observations there; those left with none die, and leave the back-end first.
  const Keyframe& v = map_.keyframe(victim);
  for (int c = 0; c < v.features.cameras(); ++c) {
    for (int k = 0; k < v.features.sets[c].count; ++k) {
      const int lm = v.landmark_of[c][k];
      if (lm < 0) continue;
      const Landmark& l = map_.landmark(lm);
      bool elsewhere = false;
      for (int o = 0; o < l.obs_count && !elsewhere; ++o) elsewhere = l.obs[o].keyframe != victim;
      if (!elsewhere) backendRemoveLandmark(lm);
    }
  }
  map_.eraseKeyframe(victim);
  return map_.createKeyframe();
}

int LocalMapper::insertKeyframe(const FrameFeatures& frame, const FrameMatches* matches, const SE3& T_w_b,
                                uint64_t frame_index, bool create_multiview_points) {
  const int slot = allocateKeyframe();
  if (slot < 0) return -1;
  Keyframe& kf = map_.keyframe(slot);
  kf.features = frame;
  kf.T_w_b = T_w_b;
  kf.t = frame.t;
  kf.frame_index = frame_index;

  if (matches) {
    for (int c = 0; c < frame.cameras(); ++c) {
      for (int k = 0; k < frame.sets[c].count; ++k) {
        const int lm = matches->landmarkOf(c, k);
        if (lm >= 0 && map_.landmark(lm).alive && map_.addObservation(lm, slot, c, k)) touch(lm);
      }
    }
    linkMultiViewPartners(slot, frame);
  }
  if (create_multiview_points) {
    for (int t = 0; t < frame.mv_count; ++t) {
      const MultiViewFeature& mv = frame.mv[t];
      if (!mv.has_point || mv.relative_depth_sigma > options_.landmark_max_depth_sigma) continue;
      bool linked = false;
      for (int r = 0; r < mv.size && !linked; ++r) {
        const KeypointRef& ref = frame.mv_refs[mv.first + r];
        linked = kf.landmark_of[ref.cam][ref.index] >= 0;
      }
      if (linked) continue;
      const int lm = map_.createLandmark(T_w_b * mv.p_b, mv.descriptor, kf.id);
      if (lm < 0) break;  // map full: keep tracking with what we have
      map_.landmark(lm).metric = true;
      for (int r = 0; r < mv.size; ++r) {
        const KeypointRef& ref = frame.mv_refs[mv.first + r];
        map_.addObservation(lm, slot, ref.cam, ref.index);
      }
      touch(lm);
    }
  }
  finishTouched();
  return slot;
}

// Keypoints of one multi-view feature see the same point: when one of them was matched to a landmark,
// the others observe it too if it projects onto them.
void LocalMapper::linkMultiViewPartners(int slot, const FrameFeatures& frame) {
  Keyframe& kf = map_.keyframe(slot);
  for (int t = 0; t < frame.mv_count; ++t) {
    const MultiViewFeature& mv = frame.mv[t];
    int lm = -1;
    for (int r = 0; r < mv.size && lm < 0; ++r) {
      const KeypointRef& ref = frame.mv_refs[mv.first + r];
      lm = kf.landmark_of[ref.cam][ref.index];
    }
    if (lm < 0) continue;
    const Landmark& l = map_.landmark(lm);
    for (int r = 0; r < mv.size; ++r) {
      const KeypointRef& ref = frame.mv_refs[mv.first + r];
      if (kf.landmark_of[ref.cam][ref.index] >= 0) continue;
      const Keypoint& kp = frame.sets[ref.cam].keypoints[ref.index];
      Vec2 uv;
      const Vec3 p_c = (kf.T_w_b * rig_state_.rig().T_b_c(ref.cam)).inverse() * l.p_w;
      if (!rig_state_.rig().model(ref.cam).project(p_c, uv)) continue;
      const double e = (uv - Vec2(kp.x, kp.y)).norm() / octave_scale_[kp.octave];
      if (e * e < 5.991 && map_.addObservation(lm, slot, ref.cam, ref.index)) touch(lm);
    }
  }
}

void LocalMapper::backendRemoveLandmark(int lm) {
  Landmark& l = map_.landmark(lm);
  if (solver_ && l.in_backend) solver_->removeLandmark(lm);
  l.in_backend = false;
}

int LocalMapper::triangulateWithPrevious(int slot) {
  Keyframe& kn = map_.keyframe(slot);
  // Previous keyframes, newest first.
  int previous[16];
  int np = 0;
  for (int want = 0; want < std::min(options_.temporal_keyframes, 16); ++want) {
    int best = -1;
    for (int i = 0; i < map_.keyframeCapacity(); ++i) {
      const Keyframe& k = map_.keyframe(i);
      if (!k.alive || k.id >= kn.id) continue;
      bool taken = false;
      for (int j = 0; j < np; ++j) taken = taken || previous[j] == i;
      if (!taken && (best < 0 || k.id > map_.keyframe(best).id)) best = i;
    }
    if (best < 0) break;
    previous[np++] = best;
  }

  const int cams = rig_state_.rig().size();
  const double min_depth = std::max(0.05, options_.new_points.min_depth);
  constexpr int kMaxHamming = 50;    // stricter than tracking: nothing else vouches for these matches
  constexpr float kRatio = 0.75f;
  constexpr double kEpipolarPx = 2.0;
  constexpr int kMaxOctaveDifference = 2;
  int created = 0;
  // Where the map's unit rests on these points (scene_referenced_points_), they are judged by the uncertainty of
  // their inverse depth against the scene's, not of their depth against their own, and without a parallax bound
  // (TriangulationOptions::reference_inverse_depth): both selected the points that noise put nearer, and a
  // one-camera map shrank at every corner (to a tenth of its first unit by the end of the rendered indoor loop). Where
  // multi-view features give every frame its metres, the own bounds stay: they reject points whose depth is
  // imprecise, which tracking takes as exact (the scene bound made 5-frame spans of the first 50 frames of the
  // 5-camera sequence up to 8% long). A keyframe without a scene yet (initialization) uses the own bounds too.
  //
  // Where the map's unit rests on these points, keypoints that already have a landmark take part in the ratio
  // test too (and are never chosen). Without them a lookalike on the epipolar line stood unopposed whenever the
  // true partner had a landmark: on the rendered indoor loop up to a quarter of the 10 cm rig's window landmarks
  // after a corner paired keypoints of points 5-20 cm apart (audited against the renderer's depth), consistent
  // with the poses that chose them, so the scale estimates agreed with the map's wrong unit. Rigs with overlap
  // keep the old rule (stereo, seven runs: 0.063 m against 0.054 m, within the runs' spread; not adopted there).
  const bool landmarks_compete = scene_referenced_points_;
  TriangulationOptions tri_options = options_.new_points;
  if (scene_referenced_points_) tri_options.reference_inverse_depth = sceneInverseDepth(slot);
  if (tri_options.reference_inverse_depth > 0) tri_options.min_parallax_deg = 0;

  for (int pi = 0; pi < np; ++pi) {
    const int po = previous[pi];
    const Keyframe& ko = map_.keyframe(po);
    int nc = 0;
    for (int c = 0; c < cams; ++c) std::fill(claim_.begin() + c * capacity_, claim_.begin() + c * capacity_ + ko.features.sets[c].count, -1);

    for (int c2 = 0; c2 < cams; ++c2) {
      if (!kn.features.present[c2]) continue;
      const SE3 T_w_c2 = kn.T_w_b * rig_state_.rig().T_b_c(c2);
      const FeatureSet& set2 = kn.features.sets[c2];
      std::fill(best_.begin(), best_.begin() + set2.count, Best{});
      for (int c1 = 0; c1 < cams; ++c1) {
        if (!ko.features.present[c1]) continue;
        const SE3 T_w_c1 = ko.T_w_b * rig_state_.rig().T_b_c(c1);
        const double axes = std::acos(std::clamp(T_w_c1.R.col(2).dot(T_w_c2.R.col(2)), -1.0, 1.0));
        if (axes > half_fov_[c1] + half_fov_[c2]) continue;  // the two views cannot share a point
        const Vec3 baseline = T_w_c2.t - T_w_c1.t;
        if (!band_index_.begin(baseline)) continue;  // no baseline: no depth from this pair
        const FeatureSet& set1 = ko.features.sets[c1];
        for (int b = 0; b < set1.count; ++b) {
          if ((!landmarks_compete && ko.landmark_of[c1][b] >= 0) || !ko.features.valid[c1][b]) continue;
          band_index_.add(b, T_w_c1.R * ko.features.bearings[c1][b], set1.keypoints[b].octave);
        }
        band_index_.finish();
        const CameraModel& m1 = rig_state_.rig().model(c1);
        const double f1 = 0.5 * (m1.fx() + m1.fy());
        for (int o = 0; o < options_.levels; ++o) gate_[o] = kEpipolarPx * octave_scale_[o] / f1;

        for (int a = 0; a < set2.count; ++a) {
          if (kn.landmark_of[c2][a] >= 0 || !kn.features.valid[c2][a]) continue;
          const Vec3 d2 = T_w_c2.R * kn.features.bearings[c2][a];
          const int oa = set2.keypoints[a].octave;
          Best& best = best_[a];
          band_index_.forEachOnPlane(d2, oa - kMaxOctaveDifference, oa + kMaxOctaveDifference, gate_.data(),
                                     [&](int32_t b, const float* d1f) {
            // The two rays must meet in front of both cameras, at least the minimum depth along the new one.
            const Vec3 d1(d1f[0], d1f[1], d1f[2]);
            const double cosine = d2.dot(d1);
            const double den = 1.0 - cosine * cosine;
            if (den > 1e-12) {
              const double along2 = d2.dot(baseline), along1 = d1.dot(baseline);
              const double t2 = (cosine * along1 - along2) / den;
              const double t1 = (along1 - cosine * along2) / den;
              if (t2 < min_depth || t1 <= 0) return;
            }
            const int d = hammingDistance(set2.descriptors[a], set1.descriptors[b]);
            if (d < best.distance) {
              best.second = best.distance;
              best.distance = d;
              best.cam = c1;
              best.kp = b;
              best.free = ko.landmark_of[c1][b] < 0;
            } else if (d < best.second) {
              best.second = d;
            }
          });
        }
      }
      for (int a = 0; a < set2.count; ++a) {
        const Best& best = best_[a];
        if (best.kp < 0 || !best.free || best.distance > kMaxHamming || !(best.distance < kRatio * best.second)) {
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
    // Triangulate every surviving candidate from all its rays: both keypoints and their multi-view partners.
    for (int i = 0; i < nc; ++i) {
      const Candidate& cand = candidates_[i];
      if (cand.distance < 0 || kn.landmark_of[cand.cam_new][cand.kp_new] >= 0) continue;
      int n = 0;
      auto addRays = [&](int kf_slot, int cam, int kp) {
        const Keyframe& k = map_.keyframe(kf_slot);
        const int mv = k.features.mv_of[cam][kp];
        auto addOne = [&](int c, int idx) {
          if (n >= static_cast<int>(tri_obs_.size()) || k.landmark_of[c][idx] >= 0) return;
          TriangulationObservation& o = tri_obs_[n];
          const Keypoint& key = k.features.sets[c].keypoints[idx];
          o.model = &rig_state_.rig().model(c);
          o.T_f_c = k.T_w_b * rig_state_.rig().T_b_c(c);
          o.uv = Vec2(key.x, key.y);
          o.bearing = k.features.bearings[c][idx];
          o.sigma_px = octave_scale_[key.octave];
          tri_refs_[n] = KeypointRef{static_cast<int16_t>(c), idx};
          tri_kf_[n] = kf_slot;
          ++n;
        };
        if (mv < 0) {
          addOne(cam, kp);
          return;
        }
        const MultiViewFeature& f = k.features.mv[mv];
        for (int r = 0; r < f.size; ++r) addOne(k.features.mv_refs[f.first + r].cam, k.features.mv_refs[f.first + r].index);
      };
      addRays(slot, cand.cam_new, cand.kp_new);
      addRays(po, cand.cam_old, cand.kp_old);
      const TriangulationResult tri = triangulate(tri_obs_.data(), n, tri_options);
      if (!tri.ok()) continue;
      const int lm = map_.createLandmark(tri.point, kn.features.sets[cand.cam_new].descriptors[cand.kp_new], kn.id);
      if (lm < 0) return created;
      for (int r = 0; r < n; ++r) map_.addObservation(lm, tri_kf_[r], tri_refs_[r].cam, tri_refs_[r].index);
      touch(lm);
      ++created;
    }
  }
  finishTouched();
  return created;
}

double LocalMapper::sceneInverseDepth(int slot) {
  constexpr int kMinLandmarks = 20;  // a median worth the name
  const Keyframe& k = map_.keyframe(slot);
  int n = 0;
  for (int c = 0; c < k.features.cameras(); ++c) {
    const Vec3 centre = k.T_w_b * rig_state_.rig().T_b_c(c).t;
    for (int i = 0; i < k.features.sets[c].count; ++i) {
      const int lm = k.landmark_of[c][i];
      if (lm < 0) continue;
      const double range = (map_.landmark(lm).p_w - centre).norm();
      if (range > 0) inverse_ranges_[n++] = 1.0 / range;
    }
  }
  return n < kMinLandmarks ? 0.0 : medianOf(inverse_ranges_, n);
}

bool LocalMapper::optimize(int slot) {
  if (!beginOptimize(slot)) return false;
  return finishOptimize();
}

bool LocalMapper::beginOptimize(int slot) {
  if (!solver_) return false;
  finishOptimize();  // one window at a time
  Keyframe& kf = map_.keyframe(slot);
  if (solver_->isFull()) {
    const std::optional<int64_t> oldest = solver_->oldestKeyframe();
    if (solver_->marginalizeOldest() != backend::Status::Ok) return false;
    if (oldest) {
      const int os = keyframeSlotOfId(*oldest);
      if (os >= 0) map_.keyframe(os).in_backend = false;
    }
    for (const int64_t id : solver_->marginalizedLandmarks()) {
      Landmark& l = map_.landmark(static_cast<int>(id));
      l.in_backend = false;
      l.frozen = true;
    }
  }
  if (solver_->addKeyframe(kf.id, kf.T_w_b) != backend::Status::Ok) return false;
  kf.in_backend = true;

  for (int c = 0; c < kf.features.cameras(); ++c) {
    for (int k = 0; k < kf.features.sets[c].count; ++k) {
      const int lm = kf.landmark_of[c][k];
      if (lm < 0) continue;
      Landmark& l = map_.landmark(lm);
      if (l.in_backend) {
        const Keypoint& kp = kf.features.sets[c].keypoints[k];
        solver_->addObservation(kf.id, lm, c, Vec2(kp.x, kp.y), octave_scale_[kp.octave]);
        continue;
      }
      if (l.frozen) continue;
      int in_window = 0;
      for (int o = 0; o < l.obs_count; ++o) in_window += map_.keyframe(l.obs[o].keyframe).in_backend ? 1 : 0;
      if (in_window < 2 || solver_->addLandmark(lm, l.p_w) != backend::Status::Ok) continue;
      l.in_backend = true;
      for (int o = 0; o < l.obs_count; ++o) {
        const Keyframe& ok = map_.keyframe(l.obs[o].keyframe);
        if (!ok.in_backend) continue;
        const Keypoint& kp = ok.features.sets[l.obs[o].cam].keypoints[l.obs[o].kp];
        solver_->addObservation(ok.id, lm, l.obs[o].cam, Vec2(kp.x, kp.y), octave_scale_[kp.octave]);
      }
    }
  }
  solving_ = true;
  if (worker_) {
    worker_->start(*solver_, options_.backend_iterations);
  } else {
    inline_summary_ = solver_->solve(options_.backend_iterations);
  }
  return true;
}

bool LocalMapper::finishOptimize() {
  if (!solving_) return false;
  solving_ = false;
  const backend::SolveSummary summary = worker_ ? worker_->wait() : inline_summary_;
  ++backend_solves_;
  // Outliers leave the back-end and the map (copied first: removing changes the solver's list).
  int no = 0;
  for (const backend::ObservationKey& o : solver_->outliers()) {
    if (no < static_cast<int>(outliers_.size())) outliers_[no++] = o;
  }
  for (int i = 0; i < no; ++i) {
    const backend::ObservationKey& o = outliers_[i];
    const int lm = static_cast<int>(o.landmark_id);
    const int ks = keyframeSlotOfId(o.keyframe_id);
    solver_->removeObservation(o);
    if (ks >= 0) map_.removeObservation(lm, ks, o.camera);
    Landmark& l = map_.landmark(lm);
    if (!l.alive) continue;
    int in_window = 0;
    for (int j = 0; j < l.obs_count; ++j) in_window += map_.keyframe(l.obs[j].keyframe).in_backend ? 1 : 0;
    if (in_window < 2) backendRemoveLandmark(lm);
    if (l.obs_count == 0) map_.eraseLandmark(lm);
  }
  if (!summary.failed) {
    for (int i = 0; i < map_.keyframeCapacity(); ++i) {
      Keyframe& k = map_.keyframe(i);
      if (k.alive && k.in_backend) solver_->keyframePose(k.id, k.T_w_b);
    }
    map_.refreshLiveList();
    for (int i = 0; i < map_.liveLandmarkCount(); ++i) {
      Landmark& l = map_.landmark(map_.liveLandmarkSlots()[i]);
      if (l.in_backend) solver_->landmarkPosition(map_.liveLandmarkSlots()[i], l.p_w);
    }
  }
  return !summary.failed;
}

uint64_t LocalMapper::backendThreadAllocations() const {
  if (!worker_) return 0;
  worker_->wait();
  return worker_->allocations();
}

int LocalMapper::cull(int newest_slot, const LandmarkTracks& tracks) {
  const int64_t newest_id = map_.keyframe(newest_slot).id;
  map_.refreshLiveList();
  int erased = 0;
  for (int i = 0; i < map_.liveLandmarkCount(); ++i) {
    const int lm = map_.liveLandmarkSlots()[i];
    const Landmark& l = map_.landmark(lm);
    if (!l.alive) continue;
    const LandmarkTrack& t = tracks.peek(map_, lm);
    const bool rarely_found = t.visible >= static_cast<uint32_t>(options_.cull_min_visible) &&
                              t.found < options_.cull_min_found_ratio * t.visible;
    const bool never_confirmed = !l.metric && l.created_keyframe_id <= newest_id - 3 && map_.observingKeyframes(lm) < 2;
    if (l.obs_count == 0 || rarely_found || never_confirmed) {
      backendRemoveLandmark(lm);
      map_.eraseLandmark(lm);
      ++erased;
    }
  }
  return erased;
}

}  // namespace mcslam
