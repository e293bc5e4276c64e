// TrackBuilder's subpixel alignment of the partners of every track to its reference keypoint (multiview:
// align_subpixel, on by default). It runs between merge() and emitTracks(), in tasks of consecutive tracks
// that the caller may spread over threads: a track's alignment reads only the frame (keypoints, bearings,
// images) and writes only its own members, counters and observations, so the result does not depend on which
// thread aligned which task, nor in which order.
#include <algorithm>
#include <cmath>

#include "mcslam/features/track_builder.hpp"

namespace mcslam {

namespace {
// Tracks per task: a few hundred microseconds of work, so that two threads end close together.
constexpr int kTracksPerAlignTask = 48;
}  // namespace

int TrackBuilder::alignTaskCount() const {
  return aligned_frame_ ? (track_count_ + kTracksPerAlignTask - 1) / kTracksPerAlignTask : 0;
}

void TrackBuilder::alignTracks(const Rig& rig, const KeypointBearings& bearings, const ImageView* images,
                               const FrameFeatures& f, int task) {
  const int begin = task * kTracksPerAlignTask, end = std::min(track_count_, begin + kTracksPerAlignTask);
  for (int t = begin; t < end; ++t) {
    if (t + 1 < end) prefetchPatches(images, f, t + 1);  // not beyond the task: another thread may be reordering it
    alignTrack(rig, bearings, images, f, t);
    // Solved here too: the triangulation is most of the emission's work, and the workers share it.
    track_solution_[t] = track_size_[t] < 2 ? TrackSolution{}
                                            : solveTrack(rig, f, members_.data() + track_first_[t],
                                                         aligned_obs_.data() + track_first_[t], track_size_[t]);
  }
}

// The alignment reads a patch around every keypoint of a track in images that the workers extracted on other
// cores, so its loads would miss this core's cache: the next track's patches are requested while this one is
// aligned.
void TrackBuilder::prefetchPatches(const ImageView* images, const FrameFeatures& f, int t) const {
  const int32_t* nodes = members_.data() + track_first_[t];
  const int h = std::clamp(options_.alignment.half_size, 1, AlignmentTemplate::kMaxHalf);
  for (int s = 0; s < track_size_[t]; ++s) {
    const int cam = nodes[s] / capacity_;
    const ImageView& im = images[cam];
    if (im.empty()) continue;
    const Keypoint& kp = f.sets[cam].keypoints[nodes[s] % capacity_];
    // The patch, its ring of derivatives and the shift bound, at this keypoint's scale (the warp between the
    // front cameras is close to a rotation at equal scale; a line missed here is only a later miss).
    const int r = static_cast<int>((h + 2) * sigma_[std::clamp<int>(kp.octave, 0, kMaxOctaves - 1)]) + 2;
    const int x0 = std::max(0, static_cast<int>(kp.x) - r), x1 = std::min(im.width - 1, static_cast<int>(kp.x) + r);
    const int y0 = std::max(0, static_cast<int>(kp.y) - r), y1 = std::min(im.height - 1, static_cast<int>(kp.y) + r);
    for (int y = y0; y <= y1; ++y) {
      const uint8_t* row = im.row(y);
      for (int x = x0 & ~63; x <= x1; x += 64) __builtin_prefetch(row + std::max(x, x0));
    }
  }
}

// Aligns every partner of track t to its reference (the finest keypoint, moved to member 0); partners whose
// patches disagree move past the track's new size and stay mono features. An aligned track's rays all pass
// through the scene point of the reference pixel: that pixel defines the point, so the reference keeps only
// the alignment's floor sigma.
void TrackBuilder::alignTrack(const Rig& rig, const KeypointBearings& bearings, const ImageView* images,
                              const FrameFeatures& f, int t) {
  int32_t* nodes = members_.data() + track_first_[t];
  Member* obs = aligned_obs_.data() + track_first_[t];
  int size = track_size_[t];
  auto keypointOf = [&](int s) -> const Keypoint& {
    return f.sets[nodes[s] / capacity_].keypoints[nodes[s] % capacity_];
  };
  int ref = 0;
  for (int s = 0; s < size; ++s) {
    const Keypoint& kp = keypointOf(s);
    obs[s] = Member{Vec2(kp.x, kp.y), f.bearings[nodes[s] / capacity_][nodes[s] % capacity_], sigma_[kp.octave], false};
    if (kp.octave < keypointOf(ref).octave) ref = s;
  }
  auto swap = [&](int a, int b) {
    std::swap(nodes[a], nodes[b]);
    std::swap(obs[a], obs[b]);
  };
  swap(0, ref);
  track_aligned_[t] = 0;
  track_disagreeing_[t] = 0;
  track_ambiguous_[t] = 0;
  // The reference side, once for all partners.
  const int ref_cam = nodes[0] / capacity_;
  const Keypoint& kr = keypointOf(0);
  ReferencePatch reference;
  Vec2 ref_uv(kr.x, kr.y);
  reference.bearing = obs[0].bearing;
  bool recentred = false;
  if (!makeReference(rig, bearings, images[ref_cam], ref_cam, kr, reference, ref_uv, recentred)) return;
  bool any = false;
  // Of the member at index 1, the partner of a track that ends with two views: the last one aligned there (a
  // partner that disagrees is replaced by the last member, aligned next at its index).
  PartnerCurve curve;
  for (int s = 1; s < size;) {
    const AlignmentStatus status =
        alignPartner(rig, images, f, nodes[0], nodes[s], reference, obs[s], s == 1 ? &curve : nullptr);
    if (status == AlignmentStatus::Disagrees) {
      ++track_disagreeing_[t];
      swap(s, size - 1);
      --size;
      continue;
    }
    any = any || status == AlignmentStatus::Ok;
    if (status == AlignmentStatus::Ok) ++track_aligned_[t];
    ++s;
  }
  if (any) {
    obs[0].sigma_px = options_.alignment.sigma_floor_spacings * sigma_[kr.octave];
    if (recentred) {
      obs[0].uv = ref_uv;
      obs[0].bearing = reference.bearing;
      obs[0].aligned = true;  // its keypoint moves with it
    }
  }
  if (size == 2 && options_.unique_two_view && ambiguousPair(images, nodes, obs, reference, curve)) {
    track_ambiguous_[t] = 1;
    size = 0;  // dropped: its keypoints stay mono features
  }
  track_size_[t] = size;
}

// Whether the partner of a two-view track (member 1, aligned) could as well be a repetition of the true one: a
// place further along its epipolar curve that looks like it (repeatsAlongEpipolar()) aligns to the reference
// patch at least as well as the match did. On repeating texture the detector keeps some of many equal corners,
// and when it missed the true partner the ratio test among keypoints passes a repetition; the true place then
// correlates better with the reference than the repetition (same surface, same details). Where the match is the
// true partner, its repetitions correlate less: those tracks stay.
bool TrackBuilder::ambiguousPair(const ImageView* images, const int32_t* nodes, const Member* obs,
                                 const ReferencePatch& ref, const PartnerCurve& curve) const {
  if (!obs[1].aligned) return false;
  constexpr int kMaxRepeats = 8;  // cost bound: the nearest repetitions on either side
  int offsets[kMaxRepeats];
  const ImageView& image = images[nodes[1] / capacity_];
  const EpipolarRepeatSearch& s = curve.search;
  const int n =
      repeatsAlongEpipolar(image, s, options_.alignment.half_size, options_.alignment.min_zncc, offsets, kMaxRepeats);
  for (int k = 0; k < n; ++k) {
    const Vec2 start = s.uv + offsets[k] * s.spacing * s.direction;
    const EpipolarAlignment other =
        alignAlongEpipolar(ref.patch, image, start, s.direction, curve.warp, s.spacing, options_.alignment);
    if (other.ok() && other.zncc >= curve.zncc) return true;
  }
  return false;
}

// The reference patch of keypoint kp of camera `cam` at ref_uv (and ref.bearing), recentred on its information
// when the options ask (then ref_uv, ref.bearing and `recentred` say where), with the pseudo-inverse of its
// projection's Jacobian. False when the patch cannot be sampled: every partner would be NotRefinable.
bool TrackBuilder::makeReference(const Rig& rig, const KeypointBearings& bearings, const ImageView& image, int cam,
                                 const Keypoint& kp, ReferencePatch& ref, Vec2& ref_uv, bool& recentred) const {
  if (!makeAlignmentTemplate(image, ref_uv, sigma_[kp.octave], options_.alignment, ref.patch)) return false;
  if (options_.recentre_reference) {
    // The corner's pixel is where FAST found it, up to its ring's radius from the structure that the patch
    // aligns (at a silhouette: the edge, while the pixel shows the background behind it).
    const Vec2 moved = ref_uv + informationCentroid(ref.patch);
    Vec3 bearing;
    if (bearings.bearingOf(rig, cam, moved, bearing)) {
      if (makeAlignmentTemplate(image, moved, sigma_[kp.octave], options_.alignment, ref.patch)) {
        ref_uv = moved;
        ref.bearing = bearing;
        recentred = true;
      } else if (!makeAlignmentTemplate(image, ref_uv, sigma_[kp.octave], options_.alignment,
                                        ref.patch)) {  // the failed attempt overwrote it: sampled again
        return false;
      }
    }
  }
  Vec2 uv_r;
  Mat23 J_r;
  if (!rig.model(cam).project(ref.bearing, uv_r, &J_r)) return false;
  ref.J_pinv = J_r.transpose() * (J_r * J_r.transpose()).inverse();
  return true;
}

// The partner's keypoint aligned to what the reference keypoint shows: the epipolar curve of the reference
// pixel in the partner camera is Y(rho) = rho * b + m in that camera's frame (rho: inverse range along the
// reference ray; rho = 0 is the point at infinity), the start is the partner keypoint projected onto it, and
// the patch warp is the derivative of the reference pixel -> partner pixel map there. ref: the track's
// reference patch and the pseudo-inverse of its projection's Jacobian at the unit bearing. Fills `out` when Ok.
AlignmentStatus TrackBuilder::alignPartner(const Rig& rig, const ImageView* images, const FrameFeatures& f,
                                           int ref_node, int node, const ReferencePatch& ref, Member& out,
                                           PartnerCurve* curve) const {
  const int r_cam = ref_node / capacity_;
  const int p_cam = node / capacity_, p_index = node % capacity_;
  const ImageView& image = images[p_cam];
  if (image.empty()) return AlignmentStatus::NotRefinable;
  const SE3& T_b_r = rig.T_b_c(r_cam);
  const SE3& T_b_p = rig.T_b_c(p_cam);
  const CameraModel& model_p = rig.model(p_cam);
  const Vec3& bearing_r = ref.bearing;
  const Mat3 R_p_b = T_b_p.R.transpose();
  const Vec3 b = R_p_b * (T_b_r.t - T_b_p.t);
  const Vec3 m = R_p_b * (T_b_r.R * bearing_r);

  // Start: the inverse range where the two rays pass closest, then Gauss-Newton onto the partner keypoint.
  const Keypoint& kp = f.sets[p_cam].keypoints[p_index];
  const Vec2 uv_kp(kp.x, kp.y);
  const Vec3& bearing_p = f.bearings[p_cam][p_index];
  const double cos_rays = m.dot(bearing_p);
  const Vec3 w0 = -b;  // partner centre minus reference centre, partner frame
  double rho = 0;
  if (1 - cos_rays * cos_rays > 1e-12) {
    const double range = (-w0.dot(m) + cos_rays * w0.dot(bearing_p)) / (1 - cos_rays * cos_rays);
    if (range > options_.triangulation.min_depth) rho = 1.0 / range;
  }
  // Within half a pixel of the keypoint the curve is straight to far below the alignment's precision: the
  // last step is taken on the tangent rather than projected again (each projection through the lens model is a
  // sizeable share of a partner's cost).
  Vec2 uv;
  Mat23 J;
  Vec2 g = Vec2::Zero();
  for (int it = 0;; ++it) {
    if (!model_p.project(rho * b + m, uv, &J)) return AlignmentStatus::NotRefinable;
    g = J * b;
    const double gg = g.squaredNorm();
    if (!(gg > 1e-12)) return AlignmentStatus::NotRefinable;  // the reference ray runs along the baseline
    const double step = std::max(-rho, g.dot(uv_kp - uv) / gg);
    rho += step;
    if (step * step * gg < 0.25 || it == 2) {
      uv += step * g;
      break;
    }
  }
  // Patch warp: a reference pixel offset moves the point normal to the reference ray (pseudo-inverse of the
  // reference projection's Jacobian at the unit bearing; the range cancels against the partner's Jacobian at Y).
  const Mat2 A = J * (R_p_b * T_b_r.R) * ref.J_pinv;
  const double g_norm = g.norm();
  const EpipolarAlignment a =
      alignAlongEpipolar(ref.patch, image, uv, g / g_norm, A, sigma_[kp.octave], options_.alignment);
  if (a.ok()) {
    // The aligned point lies on the curve: its bearing is the curve's at the shifted inverse range.
    out.uv = a.uv;
    out.bearing = (m + (rho + a.shift / g_norm) * b).normalized();
    out.sigma_px = a.sigma_px;
    out.aligned = true;
  }
  if (a.ok() && curve != nullptr) {
    // The depths the matcher accepts, from infinity (rho = 0) to the nearest, as sample offsets from the match.
    const double rho_match = rho + a.shift / g_norm, spacing = sigma_[kp.octave];
    EpipolarRepeatSearch& s = curve->search;
    s.uv = a.uv;
    s.direction = g / g_norm;
    s.spacing = spacing;
    const double bound = EpipolarRepeatSearch::kMaxOffset;
    s.lowest = static_cast<int>(std::clamp(std::ceil(-rho_match * g_norm / spacing), -bound, bound));
    s.highest = static_cast<int>(
        std::clamp(std::floor((1.0 / options_.triangulation.min_depth - rho_match) * g_norm / spacing), -bound, bound));
    curve->warp = A;
    curve->zncc = a.zncc;
  }
  return a.status;
}

}  // namespace mcslam
