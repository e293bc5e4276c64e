#include "mcslam/features/track_builder.hpp"

#include <algorithm>
#include <cmath>

#include "mcslam/core/error.hpp"

namespace mcslam {

TrackBuilder::TrackBuilder(const OverlapMap& overlap, const MultiViewOptions& options, int capacity)
    : overlap_(overlap), options_(options), capacity_(capacity) {
  const int n = overlap.cameras();
  if (n > 64) throw InputError("multi-view features support at most 64 cameras per rig");
  min_metric_views_ = options_.min_metric_views;
  if (min_metric_views_ <= 0) {
    min_metric_views_ = 2;
    for (int c = 0; c < n; ++c) {
      int partners = 0;
      for (int d = 0; d < n; ++d) partners += overlap.overlaps(c, d) || overlap.overlaps(d, c) ? 1 : 0;
      if (partners >= 2) min_metric_views_ = 3;
    }
  }
  const std::size_t pairs = overlap.overlappingPairs().size();
  order_.resize(std::max<std::size_t>(1, pairs * capacity_));
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
  track_ambiguous_.resize(parent_.size());
  aligned_obs_.resize(parent_.size());
  track_solution_.resize(parent_.size());
}

void TrackBuilder::merge(const FrameFeatures& f, std::span<const PairMatch> matches, bool align) {
  stats_ = MultiViewStats{};
  stats_.pair_matches = static_cast<int>(matches.size());
  joinMatches(f, matches);
  listTracks(f);
  aligned_frame_ = align;
}

int TrackBuilder::find(int node) {
  while (parent_[node] != node) {
    parent_[node] = parent_[parent_[node]];  // path halving
    node = parent_[node];
  }
  return node;
}

void TrackBuilder::joinMatches(const FrameFeatures& f, std::span<const PairMatch> matches) {
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
  const int match_count = static_cast<int>(matches.size());
  std::fill(distance_count_.begin(), distance_count_.end(), 0);
  for (int m = 0; m < match_count; ++m) ++distance_count_[matches[m].distance + 1];
  for (int d = 0; d < 257; ++d) distance_count_[d + 1] += distance_count_[d];
  for (int m = 0; m < match_count; ++m) order_[distance_count_[matches[m].distance]++] = m;

  for (int o = 0; o < match_count; ++o) {
    const PairMatch& m = matches[order_[o]];
    const int ra = find(m.cam_a * capacity_ + m.kp_a);
    const int rb = find(m.cam_b * capacity_ + m.kp_b);
    if (ra == rb) continue;
    if (camera_mask_[ra] & camera_mask_[rb]) continue;  // would put two keypoints of one camera in a track
    parent_[rb] = ra;
    camera_mask_[ra] |= camera_mask_[rb];
  }
}

// Components of two or more keypoints become tracks, listed in keypoint order: count, place, list.
void TrackBuilder::listTracks(const FrameFeatures& f) {
  const int cams = f.cameras();
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
void TrackBuilder::emitTracks(const Rig& rig, FrameFeatures& f) {
  for (int t = 0; t < track_count_; ++t) {
    int32_t* nodes = members_.data() + track_first_[t];
    Member* obs = aligned_obs_.data() + track_first_[t];
    TrackSolution solution;
    if (aligned_frame_) {
      solution = track_solution_[t];  // solved by alignTracks()
      stats_.aligned += track_aligned_[t];
      stats_.disagreeing += track_disagreeing_[t];
      stats_.ambiguous += track_ambiguous_[t];
    } else {
      for (int s = 0; s < track_size_[t]; ++s) {
        const Keypoint& kp = f.sets[nodes[s] / capacity_].keypoints[nodes[s] % capacity_];
        obs[s] =
            Member{Vec2(kp.x, kp.y), f.bearings[nodes[s] / capacity_][nodes[s] % capacity_], sigma_[kp.octave], false};
      }
      solution = solveTrack(rig, f, nodes, obs, track_size_[t]);
    }
    emitTrack(f, nodes, obs, solution);
  }
  aligned_frame_ = false;
}

// Triangulates a track from its members' observations and decides whether it stays a multi-view feature. Reads
// only the frame and the track; reorders the track's nodes and observations in place (a member that disagrees
// moves past the returned size), so tracks may be solved on any threads.
TrackBuilder::TrackSolution TrackBuilder::solveTrack(const Rig& rig, const FrameFeatures& f, int32_t* nodes,
                                                     Member* obs, int size) const {
  const TriangulationResult tri = triangulateTrack(rig, nodes, obs, size);
  TrackSolution out;
  out.size = static_cast<int16_t>(size);
  out.keep = tri.status == TriangulationStatus::Ok || tri.status == TriangulationStatus::Uncertain ||
             tri.status == TriangulationStatus::LowParallax;
  out.has_point = tri.status == TriangulationStatus::Ok || tri.status == TriangulationStatus::Uncertain;
  if (out.keep && out.has_point && size == 2 && options_.two_view_visibility_check) {
    out.keep = !hiddenFromNearerCamera(rig, f, nodes, tri.point);
  }
  if (!out.keep) return out;
  out.metric = tri.status == TriangulationStatus::Ok && size >= min_metric_views_;
  out.point = tri.point;
  out.relative_depth_sigma = static_cast<float>(tri.relative_depth_sigma);
  out.medoid = medoidOf(f, nodes, size);
  return out;
}

// The track's point from all its rays; while the reprojections disagree, the worst member leaves the track
// (swapped past the new size) and the rest are triangulated again.
TriangulationResult TrackBuilder::triangulateTrack(const Rig& rig, int32_t* nodes, Member* obs, int& size) const {
  TriangulationObservation tri_obs[64];  // at most one member per camera, at most 64 cameras
  auto fillObservations = [&](int n) {
    for (int s = 0; s < n; ++s) {
      const int cam = nodes[s] / capacity_;
      TriangulationObservation& o = tri_obs[s];
      o.model = &rig.model(cam);
      o.T_f_c = rig.T_b_c(cam);
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
  return tri;
}

// Whether a present camera that should see a two-view track's point, well inside its image, contributed no
// keypoint. Only a camera nearer to one of the two than they are to each other counts: its view differs less
// from theirs than they differ from each other, so it would have matched a true corner more easily.
bool TrackBuilder::hiddenFromNearerCamera(const Rig& rig, const FrameFeatures& f, const int32_t* nodes,
                                          const Vec3& point) const {
  const int c0 = nodes[0] / capacity_, c1 = nodes[1] / capacity_;
  const double baseline = (rig.T_b_c(c0).t - rig.T_b_c(c1).t).norm();
  for (int c = 0; c < f.cameras(); ++c) {
    if (c == c0 || c == c1 || !f.present[c]) continue;
    const double nearer =
        std::min((rig.T_b_c(c).t - rig.T_b_c(c0).t).norm(), (rig.T_b_c(c).t - rig.T_b_c(c1).t).norm());
    if (!(nearer < 0.9 * baseline)) continue;
    if (!(overlap_.overlaps(c, c0) || overlap_.overlaps(c0, c) || overlap_.overlaps(c, c1) ||
          overlap_.overlaps(c1, c))) {
      continue;
    }
    const CameraModel& model = rig.model(c);
    const Vec3 p_c = rig.T_b_c(c).inverse() * point;
    if (!(p_c.norm() > options_.triangulation.min_depth)) continue;
    if (model.distortion() != Distortion::Equidistant && !(p_c.z() > options_.triangulation.min_depth)) continue;
    Vec2 uv;
    if (!model.project(p_c, uv)) continue;
    const double m = options_.visibility_margin_px;
    if (uv.x() >= m && uv.y() >= m && uv.x() <= model.width() - 1 - m && uv.y() <= model.height() - 1 - m) {
      return true;
    }
  }
  return false;
}

// The track's representative descriptor: the medoid (least total Hamming distance to the others).
int16_t TrackBuilder::medoidOf(const FrameFeatures& f, const int32_t* nodes, int size) const {
  int16_t medoid = 0;
  int best_sum = 1 << 30;
  for (int a = 0; a < size; ++a) {
    const Descriptor& da = f.sets[nodes[a] / capacity_].descriptors[nodes[a] % capacity_];
    int sum = 0;
    for (int b = 0; b < size; ++b)
      sum += hammingDistance(da, f.sets[nodes[b] / capacity_].descriptors[nodes[b] % capacity_]);
    if (sum < best_sum) {
      best_sum = sum;
      medoid = static_cast<int16_t>(a);
    }
  }
  return medoid;
}

// A solved track into f: its members in f.mv_refs from the current end, aligned keypoints moved, the feature.
void TrackBuilder::emitTrack(FrameFeatures& f, const int32_t* nodes, const Member* obs, const TrackSolution& solution) {
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
