#include "mcslam/places/place_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "pose_io.hpp"

namespace mcslam {

PlaceMap::PlaceMap(int max_keyframes, int max_points_per_keyframe)
    : keyframes_(static_cast<std::size_t>(max_keyframes)),
      points_(static_cast<std::size_t>(max_keyframes) * static_cast<std::size_t>(max_points_per_keyframe)),
      free_(static_cast<std::size_t>(max_keyframes)),
      max_points_(max_points_per_keyframe),
      newest_of_segment_(kMaxSegments, -1),
      segment_T_w_o_(kMaxSegments),
      segment_scale_(kMaxSegments, 1.0),
      segment_placed_(kMaxSegments, 0),
      segment_continues_(kMaxSegments, -1),
      file_position_(static_cast<std::size_t>(max_keyframes)) {
  clear();
}

void PlaceMap::clear() {
  for (PlaceKeyframe& k : keyframes_) k = PlaceKeyframe{};
  free_count_ = capacity();
  for (int i = 0; i < free_count_; ++i) free_[static_cast<std::size_t>(i)] = free_count_ - 1 - i;  // 0 first
  live_ = 0;
  newest_ = -1;
  std::fill(newest_of_segment_.begin(), newest_of_segment_.end(), -1);
  std::fill(segment_continues_.begin(), segment_continues_.end(), -1);
  segment_count_ = 0;
  ++reshapes_;
}

int PlaceMap::createKeyframe(int32_t segment, Timestamp t, uint64_t frame_index, const SE3& T_w_k, const SE3& T_o_k) {
  if (free_count_ == 0) return -1;
  const int slot = free_[static_cast<std::size_t>(--free_count_)];
  PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
  k = PlaceKeyframe{};
  k.alive = true;
  k.id = next_id_++;
  k.segment = segment;
  k.t = t;
  k.frame_index = frame_index;
  k.T_w_k = T_w_k;
  k.T_o_k = T_o_k;
  k.unit = segment_scale_[static_cast<std::size_t>(segment)];
  int32_t& newest = newest_of_segment_[static_cast<std::size_t>(segment)];
  k.previous = newest;
  if (newest >= 0) keyframes_[static_cast<std::size_t>(newest)].next = slot;
  newest = slot;
  newest_ = slot;
  ++live_;
  return slot;
}

bool PlaceMap::addPoint(int slot, const PlacePoint& point) {
  PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
  if (k.point_count == max_points_) return false;
  points_[static_cast<std::size_t>(slot) * static_cast<std::size_t>(max_points_) +
          static_cast<std::size_t>(k.point_count++)] = point;
  return true;
}

void PlaceMap::finishKeyframe(int slot) {
  const auto first = points_.begin() + static_cast<std::ptrdiff_t>(slot) * max_points_;
  std::sort(first, first + keyframes_[static_cast<std::size_t>(slot)].point_count,
            [](const PlacePoint& a, const PlacePoint& b) { return a.node < b.node; });
}

std::span<const PlacePoint> PlaceMap::pointsOfNode(int slot, int32_t node) const {
  const std::span<const PlacePoint> all = points(slot);
  const auto lo =
      std::lower_bound(all.begin(), all.end(), node, [](const PlacePoint& p, int32_t n) { return p.node < n; });
  auto hi = lo;
  while (hi != all.end() && hi->node == node) ++hi;
  return {all.data() + (lo - all.begin()), static_cast<std::size_t>(hi - lo)};
}

void PlaceMap::eraseKeyframe(int slot) {
  PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
  if (!k.alive) return;
  if (k.previous >= 0) keyframes_[static_cast<std::size_t>(k.previous)].next = k.next;
  if (k.next >= 0) {
    PlaceKeyframe& next = keyframes_[static_cast<std::size_t>(k.next)];
    next.previous = k.previous;
    next.unit_sigma = std::max(next.unit_sigma, k.unit_sigma);  // its motion from the previous now spans both
  }
  int32_t& newest = newest_of_segment_[static_cast<std::size_t>(k.segment)];
  if (newest == slot) newest = k.previous;
  if (newest_ == slot) newest_ = k.previous;
  k = PlaceKeyframe{};
  free_[static_cast<std::size_t>(free_count_++)] = slot;
  --live_;
}

int PlaceMap::leastNeededKeyframe(std::span<const int64_t> kept) const {
  const auto inner = [&](const PlaceKeyframe& k) { return k.alive && k.previous >= 0 && k.next >= 0; };
  const auto gap = [&](const PlaceKeyframe& k, double& metres, double& radians) {
    const PlaceKeyframe& a = keyframes_[static_cast<std::size_t>(k.previous)];
    const PlaceKeyframe& b = keyframes_[static_cast<std::size_t>(k.next)];
    metres = (b.T_w_k.t - a.T_w_k.t).norm();
    radians = rotationAngle(a.T_w_k.R, b.T_w_k.R);
  };
  double sum_m = 0, sum_rad = 0;
  int inner_count = 0;
  for (const PlaceKeyframe& k : keyframes_) {
    if (!inner(k)) continue;
    double m = 0, rad = 0;
    gap(k, m, rad);
    sum_m += m;
    sum_rad += rad;
    ++inner_count;
  }
  if (inner_count == 0) return -1;
  // A map that never turned (or never moved) ranks by the other measure alone.
  const double per_m = sum_m > 0 ? inner_count / sum_m : 0, per_rad = sum_rad > 0 ? inner_count / sum_rad : 0;
  int best = -1;
  double best_score = std::numeric_limits<double>::infinity();
  for (int slot = 0; slot < capacity(); ++slot) {
    const PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
    if (!inner(k) || std::binary_search(kept.begin(), kept.end(), k.id)) continue;
    double m = 0, rad = 0;
    gap(k, m, rad);
    const double score = m * per_m + rad * per_rad;
    if (score < best_score) {
      best_score = score;
      best = slot;
    }
  }
  return best;
}

void PlaceMap::scaleKeyframe(int slot, double s, std::span<const Vec3> camera_centers) {
  keyframes_[static_cast<std::size_t>(slot)].unit *= s;
  scalePoints(slot, s, camera_centers);
}

// What a unit changes is a point's depth along the ray of the camera that saw it; the camera's lever arm is metric.
// Scaling the body-frame position instead would move the point off that ray by (s - 1) times the lever arm, and a
// pose measured on the keyframe's points (a loop's) with it.
void PlaceMap::scalePoints(int slot, double s, std::span<const Vec3> camera_centers, int cam) {
  PlacePoint* points = points_.data() + static_cast<std::size_t>(slot) * static_cast<std::size_t>(max_points_);
  const int32_t count = keyframes_[static_cast<std::size_t>(slot)].point_count;
  for (int i = 0; i < count; ++i) {
    PlacePoint& p = points[i];
    if (cam >= 0 && p.cam != cam) continue;
    const bool known = p.cam >= 0 && static_cast<std::size_t>(p.cam) < camera_centers.size();
    const Eigen::Vector3f c = known ? Eigen::Vector3f(camera_centers[static_cast<std::size_t>(p.cam)].cast<float>())
                                    : Eigen::Vector3f::Zero();
    p.p_k = c + static_cast<float>(s) * (p.p_k - c);
  }
}

void PlaceMap::refinePose(int slot, const SE3& T_o_k) {
  ++reshapes_;  // a correction solved from the pose before would put it back
  PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
  const SE3 change = k.T_o_k.inverse() * T_o_k;
  k.T_w_k = k.T_w_k * SE3(change.R, k.unit * change.t);
  k.T_w_k.normalize();
  k.T_o_k = T_o_k;
}

SE3 PlaceMap::toWorld(int32_t segment, const SE3& T_o_b) const {
  const SE3& T_w_o = segmentPose(segment);
  return {T_w_o.R * T_o_b.R, segmentScale(segment) * (T_w_o.R * T_o_b.t) + T_w_o.t};
}

SE3 PlaceMap::toOdometry(int32_t segment, const SE3& T_w_b) const {
  return (segmentSimilarity(segment).inverse() * Sim3(T_w_b)).rigid();
}

SE3 PlaceMap::segmentPoseFor(int32_t segment, const SE3& T_w_b, const SE3& T_o_b) const {
  return (Sim3(T_w_b, segmentScale(segment)) * Sim3(T_o_b).inverse()).rigid();
}

int PlaceMap::slotOfId(int64_t id) const {
  for (int slot = 0; slot < capacity(); ++slot)
    if (keyframes_[static_cast<std::size_t>(slot)].alive && keyframes_[static_cast<std::size_t>(slot)].id == id)
      return slot;
  return -1;
}

void PlaceMap::rescaleSegment(int32_t segment, double s, const Vec3& center, uint64_t from_frame,
                              std::span<const Vec3> camera_centers) {
  ++reshapes_;
  const Vec3 center_w = toWorld(segment, SE3(Mat3::Identity(), center)).t;
  for (int slot = 0; slot < capacity(); ++slot) {
    PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
    if (!k.alive || k.segment != segment || k.frame_index < from_frame) continue;
    k.T_o_k.t = center + s * (k.T_o_k.t - center);
    k.T_w_k.t = center_w + s * (k.T_w_k.t - center_w);  // a loop's bending of the keyframe stays
    scalePoints(slot, s, camera_centers);
  }
}

int32_t PlaceMap::createSegment(const SE3& T_w_o, bool placed, int32_t continues) {
  if (segment_count_ == kMaxSegments) return -1;
  setUpSegment(segment_count_, T_w_o, placed, continues);
  return segment_count_++;
}

void PlaceMap::reuseSegment(int32_t segment, const SE3& T_w_o, bool placed, int32_t continues) {
  for (int32_t& parent : segment_continues_)
    if (parent == segment) parent = -1;
  setUpSegment(segment, T_w_o, placed, continues);
}

void PlaceMap::setUpSegment(int32_t segment, const SE3& T_w_o, bool placed, int32_t continues) {
  const auto s = static_cast<std::size_t>(segment);
  segment_T_w_o_[s] = T_w_o;
  segment_scale_[s] = 1.0;
  segment_placed_[s] = placed ? 1 : 0;
  segment_continues_[s] = continues;
}

void PlaceMap::moveSegment(int32_t segment, const SE3& T_w_o) {
  ++reshapes_;
  segment_T_w_o_[static_cast<std::size_t>(segment)] = T_w_o;
  for (PlaceKeyframe& k : keyframes_)
    if (k.alive && k.segment == segment) k.T_w_k = toWorld(segment, k.T_o_k);
}

namespace {

constexpr std::size_t kPoseBytes = 12 * sizeof(double);
constexpr std::size_t kPointBytes =
    3 * sizeof(float) + sizeof(int32_t) + sizeof(int16_t) + sizeof(int8_t) + sizeof(int64_t) + sizeof(Descriptor);
constexpr std::size_t kKeyframeBytes = sizeof(int64_t) + sizeof(int32_t) + sizeof(int64_t) + sizeof(uint64_t) +
                                       2 * kPoseBytes + 2 * sizeof(double) + 2 * sizeof(int32_t) + sizeof(uint32_t);
constexpr std::size_t kSegmentBytes = kPoseBytes + sizeof(double) + 1;

}  // namespace

std::size_t PlaceMap::keyframeFileBytes(MapFileFields fields) {
  return kKeyframeBytes - (fields.scales ? 0 : sizeof(double)) - (fields.unit_sigmas ? 0 : sizeof(double));
}
std::size_t PlaceMap::pointFileBytes() { return kPointBytes; }

std::size_t PlaceMap::maxWrittenBytes() const {
  return sizeof(int64_t) + sizeof(uint32_t) + kMaxSegments * kSegmentBytes + sizeof(uint32_t) +
         static_cast<std::size_t>(capacity()) * (kKeyframeBytes + static_cast<std::size_t>(max_points_) * kPointBytes);
}

void PlaceMap::write(ByteWriter& out) const {
  out.put<int64_t>(next_id_);
  out.put<uint32_t>(static_cast<uint32_t>(segment_count_));
  for (int s = 0; s < segment_count_; ++s) {
    putPose(out, segment_T_w_o_[static_cast<std::size_t>(s)]);
    out.put<double>(segment_scale_[static_cast<std::size_t>(s)]);
    out.put<uint8_t>(segment_placed_[static_cast<std::size_t>(s)]);
  }
  // Links as positions in the file: the reader puts the i-th keyframe written into slot i.
  std::vector<int32_t>& position = file_position_;
  int count = 0;
  for (int slot = 0; slot < capacity(); ++slot)
    position[static_cast<std::size_t>(slot)] = keyframes_[static_cast<std::size_t>(slot)].alive ? count++ : -1;
  out.put<uint32_t>(static_cast<uint32_t>(count));
  const auto linked = [&](int32_t slot) { return slot < 0 ? -1 : position[static_cast<std::size_t>(slot)]; };
  for (int slot = 0; slot < capacity(); ++slot) {
    const PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
    if (!k.alive) continue;
    out.put<int64_t>(k.id);
    out.put<int32_t>(k.segment);
    out.put<int64_t>(k.t);
    out.put<uint64_t>(k.frame_index);
    putPose(out, k.T_w_k);
    putPose(out, k.T_o_k);
    out.put<double>(k.unit);
    out.put<double>(k.unit_sigma);
    out.put<int32_t>(linked(k.previous));
    out.put<int32_t>(linked(k.next));
    out.put<uint32_t>(static_cast<uint32_t>(k.point_count));
    for (const PlacePoint& p : points(slot)) {
      for (int i = 0; i < 3; ++i) out.put<float>(p.p_k[i]);
      out.put<int32_t>(p.node);
      out.put<int16_t>(p.cam);
      out.put<int8_t>(p.octave);
      out.put<int64_t>(p.landmark_id);
      out.putBytes(p.descriptor.data(), sizeof(Descriptor));
    }
  }
}

namespace {

double takeScale(ByteReader& in, const char* what) {
  const auto s = in.take<double>(what);
  if (!(s > 0) || !std::isfinite(s)) in.fail(std::string(what) + " is " + std::to_string(s) + ", not a scale");
  return s;
}

double takeUnitSigma(ByteReader& in) {
  const auto s = in.take<double>("a keyframe's unit sigma");
  if (!(s >= 0) || !std::isfinite(s)) in.fail("a keyframe's unit sigma is " + std::to_string(s) + ", not a sigma");
  return s;
}

}  // namespace

void PlaceMap::read(ByteReader& in, int cameras, MapFileFields fields) {
  clear();
  next_id_ = in.take<int64_t>("the next keyframe id");
  const auto segments = in.take<uint32_t>("the segment count");
  if (segments > static_cast<uint32_t>(kMaxSegments))
    in.fail(std::to_string(segments) + " odometry maps (segments), more than the " + std::to_string(kMaxSegments) +
            " a map holds");
  segment_count_ = static_cast<int>(segments);
  for (int s = 0; s < segment_count_; ++s) {
    segment_T_w_o_[static_cast<std::size_t>(s)] = takePose(in, "a segment's pose");
    segment_scale_[static_cast<std::size_t>(s)] = fields.scales ? takeScale(in, "a segment's scale") : 1.0;
    segment_placed_[static_cast<std::size_t>(s)] = in.take<uint8_t>("a segment's placement") != 0 ? 1 : 0;
  }
  const auto count = in.take<uint32_t>("the keyframe count");
  if (count > static_cast<uint32_t>(capacity()))
    in.fail(std::to_string(count) + " keyframes, more than places.max_keyframes (" + std::to_string(capacity()) + ")");
  const int n = static_cast<int>(count);
  for (int slot = 0; slot < n; ++slot) {
    PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
    k.alive = true;
    k.id = in.take<int64_t>("a keyframe id");
    k.segment = in.take<int32_t>("a keyframe's segment");
    k.t = in.take<int64_t>("a keyframe's time");
    k.frame_index = in.take<uint64_t>("a keyframe's frame");
    k.T_w_k = takePose(in, "a keyframe's world pose");
    k.T_o_k = takePose(in, "a keyframe's odometry pose");
    k.unit = fields.scales ? takeScale(in, "a keyframe's unit") : 1.0;
    k.unit_sigma = fields.unit_sigmas ? takeUnitSigma(in) : 0.0;
    k.previous = in.take<int32_t>("a keyframe's predecessor");
    k.next = in.take<int32_t>("a keyframe's successor");
    const auto points = in.take<uint32_t>("a keyframe's point count");
    if (k.id < 0 || k.id >= next_id_ || k.segment < 0 || k.segment >= segment_count_ || k.previous < -1 ||
        k.previous >= n || k.next < -1 || k.next >= n)
      in.fail("keyframe " + std::to_string(k.id) + " (segment " + std::to_string(k.segment) + ", neighbours " +
              std::to_string(k.previous) + " and " + std::to_string(k.next) + ") does not belong to this map");
    if (points > static_cast<uint32_t>(max_points_))
      in.fail("keyframe " + std::to_string(k.id) + " has " + std::to_string(points) +
              " points, more than places.max_points_per_keyframe (" + std::to_string(max_points_) + ")");
    k.point_count = static_cast<int32_t>(points);
    PlacePoint* out = points_.data() + static_cast<std::size_t>(slot) * static_cast<std::size_t>(max_points_);
    for (uint32_t i = 0; i < points; ++i) {
      PlacePoint& p = out[i];
      for (int j = 0; j < 3; ++j) p.p_k[j] = in.take<float>("a point's position");
      p.node = in.take<int32_t>("a point's node");
      p.cam = in.take<int16_t>("a point's camera");
      p.octave = in.take<int8_t>("a point's octave");
      p.landmark_id = in.take<int64_t>("a point's landmark");
      in.takeBytes(p.descriptor.data(), sizeof(Descriptor), "a point's descriptor");
      if (!p.p_k.allFinite() || p.cam < 0 || p.cam >= cameras || p.octave < 0 || p.node < 0)
        in.fail("keyframe " + std::to_string(k.id) + " has a point of camera " + std::to_string(p.cam) + ", octave " +
                std::to_string(p.octave) + " that this " + std::to_string(cameras) + "-camera rig cannot have");
    }
    if (k.next < 0) newest_of_segment_[static_cast<std::size_t>(k.segment)] = slot;
    if (newest_ < 0 || k.id > keyframes_[static_cast<std::size_t>(newest_)].id) newest_ = slot;
  }
  live_ = n;
  free_count_ = capacity() - n;
  for (int i = 0; i < free_count_; ++i) free_[static_cast<std::size_t>(i)] = capacity() - 1 - i;  // slot n first
  checkChains(in);
}

// Every segment's keyframes form one chain, linked both ways, from its oldest to its newest: what the loop closer
// walks. A file that says otherwise is not one this code wrote.
void PlaceMap::checkChains(const ByteReader& in) {
  std::vector<int32_t>& visited = file_position_;
  std::fill(visited.begin(), visited.end(), 0);
  int reached = 0;
  for (int slot = 0; slot < live_; ++slot) {
    if (keyframes_[static_cast<std::size_t>(slot)].previous >= 0) continue;
    for (int s = slot; s >= 0; s = keyframes_[static_cast<std::size_t>(s)].next) {
      const PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(s)];
      const bool linked = k.next < 0 || (keyframes_[static_cast<std::size_t>(k.next)].previous == s &&
                                         keyframes_[static_cast<std::size_t>(k.next)].segment == k.segment);
      const bool tail_is_newest = k.next >= 0 || newest_of_segment_[static_cast<std::size_t>(k.segment)] == s;
      if (visited[static_cast<std::size_t>(s)]++ || !linked || !tail_is_newest)
        in.fail("the keyframes of segment " + std::to_string(k.segment) + " are not one chain");
      ++reached;
    }
  }
  if (reached != live_) in.fail("keyframes in a cycle: the segments are not chains");
}

}  // namespace mcslam
