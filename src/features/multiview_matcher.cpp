#include "mcslam/features/multiview_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

#include "mcslam/core/error.hpp"

namespace mcslam {

void FrameFeatures::allocate(int cameras, int max_features_per_camera) {
  capacity_ = max_features_per_camera;
  present.assign(cameras, 0);
  sets.assign(cameras, FeatureSet(max_features_per_camera));
  bearings.assign(cameras, std::vector<Vec3>(max_features_per_camera));
  valid.assign(cameras, std::vector<uint8_t>(max_features_per_camera));
  mv_of.assign(cameras, std::vector<int32_t>(max_features_per_camera, -1));
  mv.resize(std::max(1, cameras * max_features_per_camera / 2));
  mv_refs.resize(std::max(1, cameras * max_features_per_camera));
  clear();
}

void FrameFeatures::clear() {
  for (FeatureSet& s : sets) s.clear();
  std::fill(present.begin(), present.end(), 0);
  mv_count = 0;
  mv_ref_count = 0;
}

int FrameFeatures::keypointCount() const {
  int n = 0;
  for (const FeatureSet& s : sets) n += s.count;
  return n;
}

int FrameFeatures::monoCount() const {
  int n = 0;
  for (int c = 0; c < cameras(); ++c) {
    for (int k = 0; k < sets[c].count; ++k) n += mv_of[c][k] < 0 ? 1 : 0;
  }
  return n;
}

namespace {

// Keypoints of camera j whose bearing is within 30 degrees of the baseline are not sorted by plane angle:
// near the epipole a pixel-sized gate spans a wide range of plane angles.
constexpr double kNearEpipoleSine = 0.5;

// Hamming distances of one descriptor against candidates, in a batch (POPCNT comes from the build, see
// CMakeLists.txt).
void hammingBatch(const Descriptor& a, const Descriptor* set, const int32_t* index, int n, int16_t* out) {
  for (int k = 0; k < n; ++k) out[k] = static_cast<int16_t>(hammingDistance(a, set[index[k]]));
}

}  // namespace

MultiViewMatcher::PairScratch::PairScratch(int capacity, int max_cells)
    : plane_angle(capacity),
      sorted_b(capacity),
      sorted_angle(capacity),
      sorted_candidates(capacity),
      near_epipole_b(capacity),
      cell_stamp(max_cells, 0),
      best_for_b(capacity),
      best_dist_for_b(capacity),
      second_dist_for_b(capacity),
      candidate_b(capacity),
      candidate_dist(capacity) {}

MultiViewMatcher::MultiViewMatcher(const Rig& rig, const OverlapMap& overlap, const MultiViewOptions& options,
                                   int max_features_per_camera, int threads)
    : rig_(rig), overlap_(overlap), options_(options), capacity_(max_features_per_camera) {
  const int n = rig.size();
  if (n > 64) throw InputError("multi-view features support at most 64 cameras per rig");
  if (threads < 1) throw InputError("multi-view features: threads = " + std::to_string(threads) + ", at least 1");
  for (int o = 0; o < kMaxOctaves; ++o) {
    same_px2_[o] = (options_.duplicate_px * sigma_[o]) * (options_.duplicate_px * sigma_[o]);
  }
  min_metric_views_ = options_.min_metric_views;
  if (min_metric_views_ <= 0) {
    min_metric_views_ = 2;
    for (int c = 0; c < n; ++c) {
      int partners = 0;
      for (int d = 0; d < n; ++d) partners += overlap.overlaps(c, d) || overlap.overlaps(d, c) ? 1 : 0;
      if (partners >= 2) min_metric_views_ = 3;
    }
  }
  cell_start_.resize(n);
  cell_items_.resize(n);
  cell_of_.resize(n);
  dir_b_.resize(n);
  int max_cells = 1;
  for (int c = 0; c < n; ++c) {
    cell_start_[c].resize(overlap.grid(c).cells() + 1);
    cell_items_[c].resize(capacity_);
    cell_of_[c].resize(capacity_);
    dir_b_[c].resize(capacity_);
    const CameraModel& model = rig.model(c);
    const int cols = model.width() / kBearingGridStep + 2, rows = model.height() / kBearingGridStep + 2;
    bearing_grid_cols_.push_back(cols);
    bearing_grid_.emplace_back(static_cast<std::size_t>(cols) * rows, Vec3::Zero());
    for (int gy = 0; gy < rows; ++gy) {
      for (int gx = 0; gx < cols; ++gx) {
        Vec3 b;
        if (model.unproject(Vec2(gx * kBearingGridStep, gy * kBearingGridStep), b)) bearing_grid_[c][gy * cols + gx] = b;
      }
    }
    max_cells = std::max(max_cells, overlap.grid(c).cells());
  }
  scratch_.reserve(static_cast<std::size_t>(threads));
  for (int t = 0; t < threads; ++t) scratch_.emplace_back(capacity_, max_cells);
  const std::size_t pairs = overlap.overlappingPairs().size();
  matches_.resize(std::max<std::size_t>(1, pairs * capacity_));
  pair_matches_.assign(pairs, 0);
  order_.resize(matches_.size());
  parent_.resize(static_cast<std::size_t>(n) * capacity_);
  camera_mask_.resize(parent_.size());
  component_of_root_.resize(parent_.size());
  component_size_.resize(parent_.size());
  members_.resize(parent_.size());
  distance_count_.resize(258);
  track_first_.resize(parent_.size());
  track_size_.resize(parent_.size());
  track_aligned_.resize(parent_.size());
  track_disagreeing_.resize(parent_.size());
  aligned_obs_.resize(parent_.size());
  track_solution_.resize(parent_.size());
}

void MultiViewMatcher::compute(FrameFeatures& f, const ImageView* images) {
  beginFrame(f, images);
  for (int c = 0; c < f.cameras(); ++c) prepareCamera(f, c);
  for (int p = 0; p < pairCount(); ++p) matchPair(f, p, 0);
  finishFrame(f);
}

void MultiViewMatcher::beginFrame(FrameFeatures& f, const ImageView* images) {
  stats_ = MultiViewStats{};
  images_ = options_.align_subpixel ? images : nullptr;
  f.mv_count = 0;
  f.mv_ref_count = 0;
  std::fill(pair_matches_.begin(), pair_matches_.end(), 0);
}

void MultiViewMatcher::prepareCamera(FrameFeatures& f, int camera) {
  computeBearings(f, camera);
  bucketKeypoints(f, camera);
}

void MultiViewMatcher::matchPair(const FrameFeatures& f, int pair, int thread) {
  const auto [i, j] = pairCameras(pair);
  Match* slot = matches_.data() + static_cast<std::size_t>(pair) * capacity_;
  pair_matches_[pair] = f.present[i] && f.present[j] ? matchCameras(f, i, j, scratch_[thread], slot) : 0;
}

void MultiViewMatcher::finishFrame(FrameFeatures& f) {
  mergeFrame(f);
  for (int task = 0; task < alignTaskCount(); ++task) alignTracks(f, task);
  emitTracks(f);
}

void MultiViewMatcher::mergeFrame(FrameFeatures& f) {
  gatherMatches();
  stats_.pair_matches = match_count_;
  mergeTracks(f);
  aligned_frame_ = images_ != nullptr;
}

// The pairs' slots moved to the front, in pair order (each slot starts at or after its destination).
void MultiViewMatcher::gatherMatches() {
  match_count_ = 0;
  for (int p = 0; p < pairCount(); ++p) {
    const Match* slot = matches_.data() + static_cast<std::size_t>(p) * capacity_;
    std::copy(slot, slot + pair_matches_[p], matches_.data() + match_count_);
    match_count_ += pair_matches_[p];
  }
}

// A keypoint's bearing: interpolated on the camera's grid and polished by one Gauss-Newton step on the
// projection (the smallest bearing change that moves its projection onto the pixel); the model's iterative
// unprojection where the grid has no bearing.
bool MultiViewMatcher::bearingOf(int cam, const Vec2& uv, Vec3& bearing) const {
  const CameraModel& model = rig_.model(cam);
  const std::vector<Vec3>& grid = bearing_grid_[cam];
  const int cols = bearing_grid_cols_[cam], rows = static_cast<int>(grid.size()) / cols;
  const double gxf = uv.x() / kBearingGridStep, gyf = uv.y() / kBearingGridStep;
  const int gx = static_cast<int>(std::floor(gxf)), gy = static_cast<int>(std::floor(gyf));
  if (gx >= 0 && gy >= 0 && gx + 1 < cols && gy + 1 < rows) {
    const Vec3& b00 = grid[gy * cols + gx];
    const Vec3& b10 = grid[gy * cols + gx + 1];
    const Vec3& b01 = grid[(gy + 1) * cols + gx];
    const Vec3& b11 = grid[(gy + 1) * cols + gx + 1];
    if (b00.squaredNorm() > 0 && b10.squaredNorm() > 0 && b01.squaredNorm() > 0 && b11.squaredNorm() > 0) {
      const double ax = gxf - gx, ay = gyf - gy;
      Vec3 b = ((1 - ax) * (1 - ay)) * b00 + (ax * (1 - ay)) * b10 + ((1 - ax) * ay) * b01 + (ax * ay) * b11;
      b.normalize();
      Vec2 proj;
      Mat23 J;
      if (model.project(b, proj, &J)) {
        const Mat2 JJt = J * J.transpose();
        const Vec3 delta = J.transpose() * JJt.inverse() * (uv - proj);
        if (delta.allFinite() && delta.norm() < 1e-2) {
          bearing = (b + delta).normalized();
          return true;
        }
      }
    }
  }
  return model.unproject(uv, bearing);
}

void MultiViewMatcher::computeBearings(FrameFeatures& f, int c) {
  const Mat3 R_b_c = rig_.T_b_c(c).R;
  const FeatureSet& s = f.sets[c];
  for (int k = 0; k < s.count; ++k) {
    const bool ok = bearingOf(c, Vec2(s.keypoints[k].x, s.keypoints[k].y), f.bearings[c][k]);
    f.valid[c][k] = ok ? 1 : 0;
    f.mv_of[c][k] = -1;
    dir_b_[c][k] = R_b_c * f.bearings[c][k];
  }
}

void MultiViewMatcher::bucketKeypoints(const FrameFeatures& f, int c) {
  const CellGrid& g = overlap_.grid(c);
  std::vector<int32_t>& start = cell_start_[c];
  std::fill(start.begin(), start.end(), 0);
  const FeatureSet& s = f.sets[c];
  for (int k = 0; k < s.count; ++k) {
    const int cell = g.cellOf(s.keypoints[k].x, s.keypoints[k].y);
    cell_of_[c][k] = cell;
    if (cell >= 0) ++start[cell + 1];
  }
  for (int i = 0; i < g.cells(); ++i) start[i + 1] += start[i];
  // Fill using the start offsets as cursors, then shift them back.
  for (int k = 0; k < s.count; ++k) {
    if (cell_of_[c][k] >= 0) cell_items_[c][start[cell_of_[c][k]]++] = k;
  }
  for (int i = g.cells(); i > 0; --i) start[i] = start[i - 1];
  start[0] = 0;
}

// Epipolar geometry about the baseline: every epipolar plane of the pair contains the baseline, so it is
// one half-plane of a pencil, identified by its angle about the baseline axis. A scene point lies on the
// same half-plane seen from either camera (the two rays differ by a multiple of the baseline). Camera j's
// keypoints are sorted by that angle once per pair; each keypoint of camera i then visits only those of its
// angle window (the band around its epipolar curve), and only in the overlap map's candidate cells.
int MultiViewMatcher::matchCameras(const FrameFeatures& f, int i, int j, PairScratch& sc, Match* out) const {
  const FeatureSet& si = f.sets[i];
  const FeatureSet& sj = f.sets[j];
  const Vec3 baseline = rig_.T_b_c(j).t - rig_.T_b_c(i).t;  // body frame
  const double baseline_norm = baseline.norm();
  if (!(baseline_norm > 1e-9)) return 0;  // common centre: no epipolar geometry
  const Vec3 e = baseline / baseline_norm;
  const Vec3 u = e.unitOrthogonal();
  const Vec3 v = e.cross(u);
  const double fj = 0.5 * (rig_.model(j).fx() + rig_.model(j).fy());
  double gate[kMaxOctaves];  // sine of the largest angle to the epipolar plane, per octave of the keypoint in j
  float gate_f[kMaxOctaves];
  for (int o = 0; o < kMaxOctaves; ++o) {
    gate[o] = options_.epipolar_px * sigma_[o] / fj;
    gate_f[o] = static_cast<float>(gate[o]);
  }

  // Camera j's keypoints by plane angle; those near the epipole apart.
  int sorted = 0, near = 0;
  double min_sine = 1.0;
  for (int b = 0; b < sj.count; ++b) {
    if (!f.valid[j][b] || cell_of_[j][b] < 0) continue;
    const Vec3& d = dir_b_[j][b];
    const double x = u.dot(d), y = v.dot(d);
    const double sine = std::sqrt(x * x + y * y);  // of the angle between the bearing and the baseline
    if (sine < kNearEpipoleSine) {
      sc.near_epipole_b[near++] = b;
      continue;
    }
    sc.plane_angle[b] = static_cast<float>(std::atan2(y, x));
    min_sine = std::min(min_sine, sine);
    sc.sorted_b[sorted++] = b;
  }
  // By octave, then plane angle: a keypoint of camera i scans only the octaves it may match, each with the
  // window of its own gate.
  auto octaveOf = [&](int b) { return std::clamp<int>(sj.keypoints[b].octave, 0, kMaxOctaves - 1); };
  std::sort(sc.sorted_b.begin(), sc.sorted_b.begin() + sorted, [&](int32_t p, int32_t q) {
    const int op = octaveOf(p), oq = octaveOf(q);
    return op != oq ? op < oq : sc.plane_angle[p] < sc.plane_angle[q];
  });
  int octave_start[kMaxOctaves + 1] = {};
  for (int k = 0; k < sorted; ++k) ++octave_start[octaveOf(sc.sorted_b[k]) + 1];
  for (int o = 0; o < kMaxOctaves; ++o) octave_start[o + 1] += octave_start[o];
  for (int k = 0; k < sorted; ++k) {
    const int b = sc.sorted_b[k];
    const Vec3& d = dir_b_[j][b];
    sc.sorted_angle[k] = sc.plane_angle[b];
    sc.sorted_candidates[k] = Candidate{sc.plane_angle[b], b, cell_of_[j][b], sj.keypoints[b].octave,
                                      {static_cast<float>(d.x()), static_cast<float>(d.y()), static_cast<float>(d.z())}};
  }
  // Half-width of the angle window per octave of the keypoint in j: |n . d| = sine * |sin(angle difference)|.
  double window[kMaxOctaves];
  for (int o = 0; o < kMaxOctaves; ++o) {
    const double s = gate[o] / min_sine;
    window[o] = s >= 1.0 ? M_PI : std::asin(s) + 1e-5;  // margin for the float angles
  }

  std::fill(sc.best_for_b.begin(), sc.best_for_b.begin() + sj.count, -1);
  std::fill(sc.best_dist_for_b.begin(), sc.best_dist_for_b.begin() + sj.count, int16_t{257});
  std::fill(sc.second_dist_for_b.begin(), sc.second_dist_for_b.begin() + sj.count, int16_t{257});
  int count = 0;
  const CellGrid& gi = overlap_.grid(i);
  const float* angles = sc.sorted_angle.data();

  for (int cell_i = 0; cell_i < gi.cells(); ++cell_i) {
    const int32_t begin = cell_start_[i][cell_i], end = cell_start_[i][cell_i + 1];
    if (begin == end) continue;
    const std::span<const int32_t> cells_j = overlap_.candidates(i, j, cell_i);
    if (cells_j.empty()) continue;
    if (++sc.stamp == 0) {  // wrapped: clear the old stamps
      std::fill(sc.cell_stamp.begin(), sc.cell_stamp.end(), 0u);
      sc.stamp = 1;
    }
    for (const int32_t c : cells_j) sc.cell_stamp[c] = sc.stamp;

    for (int32_t item = begin; item < end; ++item) {
      const int a = cell_items_[i][item];
      if (!f.valid[i][a]) continue;
      const Vec3& da = dir_b_[i][a];
      // Normal of the epipolar plane of keypoint a: the baseline crossed with its ray.
      Vec3 n = e.cross(da);
      const double nn = n.norm();
      if (nn < 1e-12) continue;  // the ray runs along the baseline
      n /= nn;
      const Vec3 perp = da - e * e.dot(da);  // its half-plane
      const int oa = si.keypoints[a].octave;
      int candidates = 0;
      auto consider = [&](int b) {
        if (sc.cell_stamp[cell_of_[j][b]] != sc.stamp) return;
        const int ob = sj.keypoints[b].octave;
        if (std::abs(oa - ob) > options_.max_octave_difference) return;
        const Vec3& db = dir_b_[j][b];
        if (std::abs(n.dot(db)) > gate[std::min(ob, kMaxOctaves - 1)]) return;
        sc.candidate_b[candidates++] = b;
      };
      // The same tests on the packed copy (float bearing: its rounding is far below any gate).
      const float nf[3] = {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())};
      const Candidate* packed = sc.sorted_candidates.data();
      const double angle = std::atan2(v.dot(da), u.dot(da));
      const int o_lo = std::max(0, oa - options_.max_octave_difference);
      const int o_hi = std::min(kMaxOctaves - 1, oa + options_.max_octave_difference);
      for (int ob = o_lo; ob <= o_hi; ++ob) {
        const int first_k = octave_start[ob], last_k = octave_start[ob + 1];
        if (first_k == last_k) continue;
        const float g = gate_f[ob];
        auto considerPacked = [&](const Candidate& cand) {
          if (sc.cell_stamp[cand.cell] != sc.stamp) return;
          const float dot = nf[0] * cand.d[0] + nf[1] * cand.d[1] + nf[2] * cand.d[2];
          if (std::abs(dot) > g) return;
          sc.candidate_b[candidates++] = cand.b;
        };
        const double w = window[ob];
        if (w >= M_PI) {
          for (int k = first_k; k < last_k; ++k) considerPacked(packed[k]);
          continue;
        }
        // Scans this octave's positions with angle in [lo, hi] (within [-pi, pi] after wrapping).
        auto scan = [&](double lo, double hi) {
          int k = static_cast<int>(std::lower_bound(angles + first_k, angles + last_k, static_cast<float>(lo)) - angles);
          const float hif = static_cast<float>(hi);
          for (; k < last_k && packed[k].angle <= hif; ++k) considerPacked(packed[k]);
        };
        const double lo = angle - w, hi = angle + w;
        if (lo < -M_PI) {
          scan(-M_PI, hi);
          scan(lo + 2 * M_PI, M_PI);
        } else if (hi > M_PI) {
          scan(lo, M_PI);
          scan(-M_PI, hi - 2 * M_PI);
        } else {
          scan(lo, hi);
        }
      }
      for (int k = 0; k < near; ++k) {
        const int b = sc.near_epipole_b[k];
        if (perp.dot(dir_b_[j][b]) > 0) consider(b);
      }
      if (candidates == 0) continue;
      hammingBatch(si.descriptors[a], sj.descriptors.data(), sc.candidate_b.data(), candidates,
                     sc.candidate_dist.data());
      int best = 257, best_b = -1;
      for (int c = 0; c < candidates; ++c) {
        const int d = sc.candidate_dist[c];
        const int b = sc.candidate_b[c];
        if (d < best) {
          best = d;
          best_b = b;
        }
        noteForB(si, b, a, d, sc);
      }
      if (best_b < 0 || best > options_.max_hamming) continue;
      // Ratio test against the best candidate elsewhere on the epipolar curve. The pyramid detects one corner
      // at several octaves with near-identical descriptors; such a copy of the best is no rival.
      const Keypoint& kb = sj.keypoints[best_b];
      const double same2 = same_px2_[std::clamp<int>(kb.octave, 0, kMaxOctaves - 1)];
      int second = 257;
      for (int c = 0; c < candidates; ++c) {
        const Keypoint& kc = sj.keypoints[sc.candidate_b[c]];
        const double dx = kc.x - kb.x, dy = kc.y - kb.y;
        if (sc.candidate_dist[c] < second && dx * dx + dy * dy > same2) second = sc.candidate_dist[c];
      }
      if (!(best < options_.ratio * second)) continue;
      out[count++] = Match{static_cast<int16_t>(i), static_cast<int16_t>(j), a, best_b,
                                       static_cast<int16_t>(best)};
    }
  }
  // Keep only mutual best matches that pass the ratio test both ways: b's best keypoint of camera i must be a,
  // and clearly better than any other corner of camera i on the same epipolar curve. One way is not enough:
  // on periodic texture (books, bricks, tiles) the true partner of a may be missing in j while a's repetitions
  // in camera i all compete for the same b, and along a linear camera array an alias stays consistent in all views.
  int kept = 0;
  for (int m = 0; m < count; ++m) {
    const int b = out[m].kp_b;
    if (sc.best_for_b[b] == out[m].kp_a && sc.best_dist_for_b[b] < options_.ratio * sc.second_dist_for_b[b]) {
      out[kept++] = out[m];
    }
  }
  return kept;
}

// Best and second best keypoint of camera i for keypoint b of camera j, the second ignoring copies of the best
// (the same corner detected at another octave).
void MultiViewMatcher::noteForB(const FeatureSet& si, int b, int a, int d, PairScratch& sc) const {
  const int best_a = sc.best_for_b[b];
  bool copy_of_best = false;
  if (best_a >= 0) {
    const Keypoint& ka = si.keypoints[a];
    const Keypoint& kb = si.keypoints[best_a];
    const double dx = ka.x - kb.x, dy = ka.y - kb.y;
    copy_of_best = dx * dx + dy * dy <= same_px2_[std::clamp<int>(std::max(ka.octave, kb.octave), 0, kMaxOctaves - 1)];
  }
  if (d < sc.best_dist_for_b[b]) {
    if (!copy_of_best) sc.second_dist_for_b[b] = sc.best_dist_for_b[b];
    sc.best_dist_for_b[b] = static_cast<int16_t>(d);
    sc.best_for_b[b] = a;
  } else if (d < sc.second_dist_for_b[b] && !copy_of_best) {
    sc.second_dist_for_b[b] = static_cast<int16_t>(d);
  }
}

int MultiViewMatcher::find(int node) {
  while (parent_[node] != node) {
    parent_[node] = parent_[parent_[node]];  // path halving
    node = parent_[node];
  }
  return node;
}

void MultiViewMatcher::mergeTracks(FrameFeatures& f) {
  const int cams = f.cameras();
  for (int c = 0; c < cams; ++c) {
    for (int k = 0; k < f.sets[c].count; ++k) {
      const int node = c * capacity_ + k;
      parent_[node] = node;
      camera_mask_[node] = uint64_t{1} << c;
      component_size_[node] = 0;
    }
  }
  // Best matches first (counting sort on the distance): a conflicting later match is the one dropped.
  std::fill(distance_count_.begin(), distance_count_.end(), 0);
  for (int m = 0; m < match_count_; ++m) ++distance_count_[matches_[m].distance + 1];
  for (int d = 0; d < 257; ++d) distance_count_[d + 1] += distance_count_[d];
  for (int m = 0; m < match_count_; ++m) order_[distance_count_[matches_[m].distance]++] = m;

  for (int o = 0; o < match_count_; ++o) {
    const Match& m = matches_[order_[o]];
    const int ra = find(m.cam_a * capacity_ + m.kp_a);
    const int rb = find(m.cam_b * capacity_ + m.kp_b);
    if (ra == rb) continue;
    if (camera_mask_[ra] & camera_mask_[rb]) continue;  // would put two keypoints of one camera in a track
    parent_[rb] = ra;
    camera_mask_[ra] |= camera_mask_[rb];
  }

  // Components of two or more keypoints become tracks, listed in keypoint order: count, place, emit.
  int total = 0;
  for (int c = 0; c < cams; ++c) {
    for (int k = 0; k < f.sets[c].count; ++k) ++component_size_[find(c * capacity_ + k)];
  }
  for (int c = 0; c < cams; ++c) {
    for (int k = 0; k < f.sets[c].count; ++k) {
      const int node = c * capacity_ + k;
      if (find(node) == node && component_size_[node] >= 2) {
        component_of_root_[node] = total;  // start of its members
        total += component_size_[node];
      }
    }
  }
  // component_of_root_ serves as each component's fill cursor, in keypoint order.
  int placed = 0;
  for (int c = 0; c < cams; ++c) {
    for (int k = 0; k < f.sets[c].count; ++k) {
      const int root = find(c * capacity_ + k);
      if (component_size_[root] < 2) continue;
      members_[component_of_root_[root]++] = c * capacity_ + k;
      ++placed;
    }
  }
  track_count_ = 0;
  for (int m = 0; m < placed;) {
    const int size = component_size_[find(members_[m])];
    track_first_[track_count_] = m;
    track_size_[track_count_] = size;
    ++track_count_;
    m += size;
  }
}

// The tracks in member order, each into f.mv_refs from its current end (a dropped track leaves no trace).
void MultiViewMatcher::emitTracks(FrameFeatures& f) {
  for (int t = 0; t < track_count_; ++t) {
    int32_t* nodes = members_.data() + track_first_[t];
    Member* obs = aligned_obs_.data() + track_first_[t];
    TrackSolution solution;
    if (aligned_frame_) {
      solution = track_solution_[t];  // solved by alignTracks()
      stats_.aligned += track_aligned_[t];
      stats_.disagreeing += track_disagreeing_[t];
    } else {
      for (int s = 0; s < track_size_[t]; ++s) {
        const Keypoint& kp = f.sets[nodes[s] / capacity_].keypoints[nodes[s] % capacity_];
        obs[s] = Member{Vec2(kp.x, kp.y), f.bearings[nodes[s] / capacity_][nodes[s] % capacity_], sigma_[kp.octave], false};
      }
      solution = solveTrack(f, nodes, obs, track_size_[t]);
    }
    emitTrack(f, nodes, obs, solution);
  }
  images_ = nullptr;
  aligned_frame_ = false;
}

// Triangulates a track from its members' observations and decides whether it stays a multi-view feature. Reads
// only the frame and the track; reorders the track's nodes and observations in place (a member that disagrees
// moves past the returned size), so tracks may be solved on any threads.
MultiViewMatcher::TrackSolution MultiViewMatcher::solveTrack(const FrameFeatures& f, int32_t* nodes, Member* obs,
                                                             int size) const {
  TriangulationObservation tri_obs[64];  // at most one member per camera, at most 64 cameras
  auto fillObservations = [&](int n) {
    for (int s = 0; s < n; ++s) {
      const int cam = nodes[s] / capacity_;
      TriangulationObservation& o = tri_obs[s];
      o.model = &rig_.model(cam);
      o.T_f_c = rig_.T_b_c(cam);
      o.uv = obs[s].uv;
      o.bearing = obs[s].bearing;
      o.sigma_px = obs[s].sigma_px;
    }
  };
  TriangulationResult tri;
  for (;;) {
    fillObservations(size);
    tri = triangulate(tri_obs, size, options_.triangulation);
    if (tri.status != TriangulationStatus::LargeReprojection || size <= 2) break;
    // One keypoint disagrees: drop the worst and try again.
    int worst = 0;
    double worst_err = -1;
    for (int s = 0; s < size; ++s) {
      const TriangulationObservation& o = tri_obs[s];
      Vec2 uv;
      const double e = o.model->project(o.T_f_c.inverse() * tri.point, uv) ? (uv - o.uv).norm() / o.sigma_px : 1e9;
      if (e > worst_err) {
        worst_err = e;
        worst = s;
      }
    }
    std::swap(nodes[worst], nodes[size - 1]);
    std::swap(obs[worst], obs[size - 1]);
    --size;
  }
  TrackSolution out;
  out.size = static_cast<int16_t>(size);
  out.keep = tri.status == TriangulationStatus::Ok || tri.status == TriangulationStatus::Uncertain ||
             tri.status == TriangulationStatus::LowParallax;
  out.has_point = tri.status == TriangulationStatus::Ok || tri.status == TriangulationStatus::Uncertain;
  if (out.keep && out.has_point && size == 2 && options_.two_view_visibility_check) {
    const int c0 = nodes[0] / capacity_, c1 = nodes[1] / capacity_;
    const double baseline = (rig_.T_b_c(c0).t - rig_.T_b_c(c1).t).norm();
    for (int c = 0; c < f.cameras() && out.keep; ++c) {
      if (c == c0 || c == c1 || !f.present[c]) continue;
      // Only a camera nearer to one of the two than they are to each other: its view differs less from
      // theirs than they differ from each other, so it would have matched a true corner more easily.
      const double nearer = std::min((rig_.T_b_c(c).t - rig_.T_b_c(c0).t).norm(), (rig_.T_b_c(c).t - rig_.T_b_c(c1).t).norm());
      if (!(nearer < 0.9 * baseline)) continue;
      if (!(overlap_.overlaps(c, c0) || overlap_.overlaps(c0, c) || overlap_.overlaps(c, c1) || overlap_.overlaps(c1, c))) {
        continue;
      }
      const CameraModel& model = rig_.model(c);
      const Vec3 p_c = rig_.T_b_c(c).inverse() * tri.point;
      if (!(p_c.norm() > options_.triangulation.min_depth)) continue;
      if (model.distortion() != Distortion::Equidistant && !(p_c.z() > options_.triangulation.min_depth)) continue;
      Vec2 uv;
      if (!model.project(p_c, uv)) continue;
      const double m = options_.visibility_margin_px;
      if (uv.x() >= m && uv.y() >= m && uv.x() <= model.width() - 1 - m && uv.y() <= model.height() - 1 - m) {
        out.keep = false;  // a camera that should see the point has no keypoint in the track
      }
    }
  }
  if (!out.keep) return out;
  out.metric = tri.status == TriangulationStatus::Ok && size >= min_metric_views_;
  out.point = tri.point;
  out.relative_depth_sigma = static_cast<float>(tri.relative_depth_sigma);
  // Representative descriptor: the medoid (least total Hamming distance to the others).
  int best_sum = 1 << 30;
  for (int a = 0; a < size; ++a) {
    const Descriptor& da = f.sets[nodes[a] / capacity_].descriptors[nodes[a] % capacity_];
    int sum = 0;
    for (int b = 0; b < size; ++b) sum += hammingDistance(da, f.sets[nodes[b] / capacity_].descriptors[nodes[b] % capacity_]);
    if (sum < best_sum) {
      best_sum = sum;
      out.medoid = static_cast<int16_t>(a);
    }
  }
  return out;
}

// A solved track into f: its members in f.mv_refs from the current end, aligned keypoints moved, the feature.
void MultiViewMatcher::emitTrack(FrameFeatures& f, const int32_t* nodes, const Member* obs, const TrackSolution& solution) {
  if (!solution.keep) {
    ++stats_.dropped;
    return;  // its keypoints stay mono features
  }
  const int first = f.mv_ref_count, size = solution.size;
  for (int s = 0; s < size; ++s) {
    KeypointRef& r = f.mv_refs[first + s];
    r = KeypointRef{static_cast<int16_t>(nodes[s] / capacity_), nodes[s] % capacity_};
    // Aligned partners keep their aligned position: the odometry observes the point where the track saw it.
    if (obs[s].aligned) {
      Keypoint& kp = f.sets[r.cam].keypoints[r.index];
      kp.x = static_cast<float>(obs[s].uv.x());
      kp.y = static_cast<float>(obs[s].uv.y());
      f.bearings[r.cam][r.index] = obs[s].bearing;
    }
    f.mv_of[r.cam][r.index] = f.mv_count;
  }
  MultiViewFeature& mv = f.mv[f.mv_count];
  mv.first = first;
  mv.size = static_cast<int16_t>(size);
  mv.has_point = solution.has_point;
  mv.metric = solution.metric;
  mv.p_b = solution.point;
  mv.relative_depth_sigma = solution.relative_depth_sigma;
  const KeypointRef& rm = f.mv_refs[first + solution.medoid];
  mv.descriptor = f.sets[rm.cam].descriptors[rm.index];
  ++f.mv_count;
  f.mv_ref_count += size;
  ++stats_.tracks;
  stats_.tracks_with_point += mv.has_point ? 1 : 0;
  stats_.metric_tracks += mv.metric ? 1 : 0;
}

}  // namespace mcslam
