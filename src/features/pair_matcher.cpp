#include "mcslam/features/pair_matcher.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam {

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

PairMatcher::PairScratch::PairScratch(int capacity, int max_cells)
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

PairMatcher::PairMatcher(const OverlapMap& overlap, const MultiViewOptions& options, int capacity, int threads)
    : overlap_(overlap), options_(options), capacity_(capacity) {
  const int n = overlap.cameras();
  for (int o = 0; o < kMaxOctaves; ++o) {
    same_px2_[o] = (options_.duplicate_px * sigma_[o]) * (options_.duplicate_px * sigma_[o]);
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
    max_cells = std::max(max_cells, overlap.grid(c).cells());
  }
  scratch_.reserve(static_cast<std::size_t>(threads));
  for (int t = 0; t < threads; ++t) scratch_.emplace_back(capacity_, max_cells);
  const std::size_t pairs = overlap.overlappingPairs().size();
  matches_.resize(std::max<std::size_t>(1, pairs * capacity_));
  pair_matches_.assign(pairs, 0);
}

void PairMatcher::beginFrame() { std::fill(pair_matches_.begin(), pair_matches_.end(), 0); }

void PairMatcher::prepareCamera(const Rig& rig, const FrameFeatures& f, int c) {
  const Mat3 R_b_c = rig.T_b_c(c).R;
  for (int k = 0; k < f.sets[c].count; ++k) dir_b_[c][k] = R_b_c * f.bearings[c][k];
  bucketKeypoints(f, c);
}

void PairMatcher::matchPair(const Rig& rig, const FrameFeatures& f, int pair, int thread) {
  const auto [i, j] = pairCameras(pair);
  PairMatch* slot = matches_.data() + static_cast<std::size_t>(pair) * capacity_;
  pair_matches_[pair] = f.present[i] && f.present[j] ? matchCameras(rig, f, i, j, scratch_[thread], slot) : 0;
}

// The pairs' slots moved to the front, in pair order (each slot starts at or after its destination).
std::span<const PairMatch> PairMatcher::gather() {
  int count = 0;
  for (int p = 0; p < pairCount(); ++p) {
    const PairMatch* slot = matches_.data() + static_cast<std::size_t>(p) * capacity_;
    std::copy(slot, slot + pair_matches_[p], matches_.data() + count);
    count += pair_matches_[p];
  }
  return {matches_.data(), static_cast<std::size_t>(count)};
}

void PairMatcher::bucketKeypoints(const FrameFeatures& f, int c) {
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
int PairMatcher::matchCameras(const Rig& rig, const FrameFeatures& f, int i, int j, PairScratch& sc,
                              PairMatch* out) const {
  const FeatureSet& sj = f.sets[j];
  const Vec3 baseline = rig.T_b_c(j).t - rig.T_b_c(i).t;  // body frame
  const double baseline_norm = baseline.norm();
  if (!(baseline_norm > 1e-9)) return 0;  // common centre: no epipolar geometry
  PairGeometry g;
  g.e = baseline / baseline_norm;
  g.u = g.e.unitOrthogonal();
  g.v = g.e.cross(g.u);
  const double fj = 0.5 * (rig.model(j).fx() + rig.model(j).fy());
  for (int o = 0; o < kMaxOctaves; ++o) {
    g.gate[o] = options_.epipolar_px * sigma_[o] / fj;
    g.gate_f[o] = static_cast<float>(g.gate[o]);
  }
  arrangeCandidates(f, j, sc, g);

  std::fill(sc.best_for_b.begin(), sc.best_for_b.begin() + sj.count, -1);
  std::fill(sc.best_dist_for_b.begin(), sc.best_dist_for_b.begin() + sj.count, int16_t{257});
  std::fill(sc.second_dist_for_b.begin(), sc.second_dist_for_b.begin() + sj.count, int16_t{257});
  int count = 0;
  const CellGrid& gi = overlap_.grid(i);
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
      const int candidates = epipolarCandidates(f, i, j, a, g, sc);
      if (candidates == 0) continue;
      const int best = bestOfCandidates(f, i, j, a, candidates, sc);
      if (best < 0) continue;
      out[count++] =
          PairMatch{static_cast<int16_t>(i), static_cast<int16_t>(j), a, sc.candidate_b[best], sc.candidate_dist[best]};
    }
  }
  // Keep only mutual best matches that pass the ratio test both ways: b's best keypoint of camera i must be a,
  // and clearly better than any other corner of camera i on the same epipolar curve. One way is not enough:
  // on periodic texture (books, bricks, tiles) the true partner of a may be missing in j while a's repetitions
  // in camera i all compete for the same b, and along a linear camera array an alias stays consistent in all views.
  int kept = 0;
  for (int m = 0; m < count; ++m) {
    const int b = out[m].kp_b;
    if (sc.best_for_b[b] == out[m].kp_a &&
        passesRatioTest(sc.best_dist_for_b[b], sc.second_dist_for_b[b], options_.ratio)) {
      out[kept++] = out[m];
    }
  }
  return kept;
}

// Camera j's keypoints by octave, then plane angle (a keypoint of camera i scans only the octaves it may match,
// each with the window of its own gate); those near the epipole apart.
void PairMatcher::arrangeCandidates(const FrameFeatures& f, int j, PairScratch& sc, PairGeometry& g) const {
  const FeatureSet& sj = f.sets[j];
  int sorted = 0, near = 0;
  double min_sine = 1.0;
  for (int b = 0; b < sj.count; ++b) {
    if (!f.valid[j][b] || cell_of_[j][b] < 0) continue;
    const Vec3& d = dir_b_[j][b];
    const double x = g.u.dot(d), y = g.v.dot(d);
    const double sine = std::sqrt(x * x + y * y);  // of the angle between the bearing and the baseline
    if (sine < kNearEpipoleSine) {
      sc.near_epipole_b[near++] = b;
      continue;
    }
    sc.plane_angle[b] = static_cast<float>(std::atan2(y, x));
    min_sine = std::min(min_sine, sine);
    sc.sorted_b[sorted++] = b;
  }
  g.near = near;
  auto octaveOf = [&](int b) { return std::clamp<int>(sj.keypoints[b].octave, 0, kMaxOctaves - 1); };
  std::sort(sc.sorted_b.begin(), sc.sorted_b.begin() + sorted, [&](int32_t p, int32_t q) {
    const int op = octaveOf(p), oq = octaveOf(q);
    return op != oq ? op < oq : sc.plane_angle[p] < sc.plane_angle[q];
  });
  std::fill(g.octave_start, g.octave_start + kMaxOctaves + 1, 0);
  for (int k = 0; k < sorted; ++k) ++g.octave_start[octaveOf(sc.sorted_b[k]) + 1];
  for (int o = 0; o < kMaxOctaves; ++o) g.octave_start[o + 1] += g.octave_start[o];
  for (int k = 0; k < sorted; ++k) {
    const int b = sc.sorted_b[k];
    const Vec3& d = dir_b_[j][b];
    sc.sorted_angle[k] = sc.plane_angle[b];
    sc.sorted_candidates[k] =
        Candidate{sc.plane_angle[b],
                  b,
                  cell_of_[j][b],
                  sj.keypoints[b].octave,
                  {static_cast<float>(d.x()), static_cast<float>(d.y()), static_cast<float>(d.z())}};
  }
  // Half-width of the angle window per octave of the keypoint in j: |n . d| = sine * |sin(angle difference)|.
  for (int o = 0; o < kMaxOctaves; ++o) {
    const double s = g.gate[o] / min_sine;
    g.window[o] = s >= 1.0 ? M_PI : std::asin(s) + 1e-5;  // margin for the float angles
  }
}

// Keypoint a of camera i: the keypoints of camera j within its epipolar gate, in its candidate cells and octaves,
// into s.candidate_b. Returns their count.
int PairMatcher::epipolarCandidates(const FrameFeatures& f, int i, int j, int a, const PairGeometry& g,
                                    PairScratch& sc) const {
  const FeatureSet& sj = f.sets[j];
  const Vec3& e = g.e;
  const Vec3& da = dir_b_[i][a];
  // Normal of the epipolar plane of keypoint a: the baseline crossed with its ray.
  Vec3 n = e.cross(da);
  const double nn = n.norm();
  if (nn < 1e-12) return 0;  // the ray runs along the baseline
  n /= nn;
  const Vec3 perp = da - e * e.dot(da);  // its half-plane
  const int oa = f.sets[i].keypoints[a].octave;
  int candidates = 0;
  auto consider = [&](int b) {
    if (sc.cell_stamp[cell_of_[j][b]] != sc.stamp) return;
    const int ob = sj.keypoints[b].octave;
    if (std::abs(oa - ob) > options_.max_octave_difference) return;
    const Vec3& db = dir_b_[j][b];
    if (std::abs(n.dot(db)) > g.gate[std::min(ob, kMaxOctaves - 1)]) return;
    sc.candidate_b[candidates++] = b;
  };
  // The same tests on the packed copy (float bearing: its rounding is far below any gate).
  const float nf[3] = {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())};
  const Candidate* packed = sc.sorted_candidates.data();
  const float* angles = sc.sorted_angle.data();
  const double angle = std::atan2(g.v.dot(da), g.u.dot(da));
  const int o_lo = std::max(0, oa - options_.max_octave_difference);
  const int o_hi = std::min(kMaxOctaves - 1, oa + options_.max_octave_difference);
  for (int ob = o_lo; ob <= o_hi; ++ob) {
    const int first_k = g.octave_start[ob], last_k = g.octave_start[ob + 1];
    if (first_k == last_k) continue;
    const float gate = g.gate_f[ob];
    auto considerPacked = [&](const Candidate& cand) {
      if (sc.cell_stamp[cand.cell] != sc.stamp) return;
      const float dot = nf[0] * cand.d[0] + nf[1] * cand.d[1] + nf[2] * cand.d[2];
      if (std::abs(dot) > gate) return;
      sc.candidate_b[candidates++] = cand.b;
    };
    const double w = g.window[ob];
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
  for (int k = 0; k < g.near; ++k) {
    const int b = sc.near_epipole_b[k];
    if (perp.dot(dir_b_[j][b]) > 0) consider(b);
  }
  return candidates;
}

// The best of keypoint a's candidates (its index in s.candidate_b), or -1 when it is too far or not clearly
// better than the second best. Notes every candidate's distance for the test the other way (noteForB()).
int PairMatcher::bestOfCandidates(const FrameFeatures& f, int i, int j, int a, int candidates, PairScratch& sc) const {
  const FeatureSet& si = f.sets[i];
  const FeatureSet& sj = f.sets[j];
  hammingBatch(si.descriptors[a], sj.descriptors.data(), sc.candidate_b.data(), candidates, sc.candidate_dist.data());
  int best = 257, best_c = -1;
  for (int c = 0; c < candidates; ++c) {
    const int d = sc.candidate_dist[c];
    const int b = sc.candidate_b[c];
    if (d < best) {
      best = d;
      best_c = c;
    }
    noteForB(si, b, a, d, sc);
  }
  if (best_c < 0 || best > options_.max_hamming) return -1;
  // Ratio test against the best candidate elsewhere on the epipolar curve. The pyramid detects one corner
  // at several octaves with near-identical descriptors; such a copy of the best is no rival.
  const Keypoint& kb = sj.keypoints[sc.candidate_b[best_c]];
  const double same2 = same_px2_[std::clamp<int>(kb.octave, 0, kMaxOctaves - 1)];
  int second = 257;
  for (int c = 0; c < candidates; ++c) {
    const Keypoint& kc = sj.keypoints[sc.candidate_b[c]];
    const double dx = kc.x - kb.x, dy = kc.y - kb.y;
    if (sc.candidate_dist[c] < second && dx * dx + dy * dy > same2) second = sc.candidate_dist[c];
  }
  if (!passesRatioTest(best, second, options_.ratio)) return -1;
  return best_c;
}

// Best and second best keypoint of camera i for keypoint b of camera j, the second ignoring copies of the best
// (the same corner detected at another octave).
void PairMatcher::noteForB(const FeatureSet& si, int b, int a, int d, PairScratch& sc) const {
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

}  // namespace mcslam
