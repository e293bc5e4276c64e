#include "synthetic_sequence.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "mcslam/calib/calibration_io.hpp"
#include "test_support.hpp"

namespace mcslam::test {

Rig isecRig() { return loadKalibrRig(dataPath("calib/isec_5cam_camchain.yaml")); }

Rig nonOverlappingRig3() {
  const Rig full = isecRig();
  Rig rig;
  RigCamera front = full.cameras[2];
  front.T_b_c = SE3();
  rig.cameras.push_back(front);
  for (double yaw : {-M_PI / 2, M_PI / 2}) {
    RigCamera side = front;
    side.T_b_c = SE3(Eigen::AngleAxisd(yaw, Vec3::UnitY()).toRotationMatrix(), Vec3(0.0, 0.0, -0.1));
    rig.cameras.push_back(side);
  }
  for (int i = 0; i < rig.size(); ++i) rig.cameras[i].name = "cam" + std::to_string(i);
  return rig;
}

namespace {
// World: z up. Body: camera-like (x right, y down, z forward), moving in the horizontal plane.
// A loop with a wobble: the heading changes at varying rates (up to ~40 deg/s at 1 m/s).
Vec3 circlePointAt(double a, double radius) {
  const double r = radius * (1.0 + 0.25 * std::sin(3.0 * a));
  return Vec3(r * std::cos(a), r * std::sin(a), 0.6);
}

// A rounded rectangle, counter-clockwise from the middle of its lower side's straight.
Vec3 rectanglePoint(double s, double side_x, double side_y) {
  constexpr double kCorner = 1.2;
  const double straight[2] = {side_x - 2 * kCorner, side_y - 2 * kCorner}, arc = 0.5 * M_PI * kCorner;
  s = std::fmod(s, 2 * (straight[0] + straight[1]) + 4 * arc);
  Vec3 start(-0.5 * side_x + kCorner, -0.5 * side_y, 0.6);
  double heading = 0;
  for (int k = 0; k < 4; ++k) {
    const Vec3 along(std::cos(heading), std::sin(heading), 0), left(-std::sin(heading), std::cos(heading), 0);
    if (s < straight[k % 2]) return start + s * along;
    s -= straight[k % 2];
    const Vec3 centre = start + straight[k % 2] * along + kCorner * left;
    if (s < arc) {
      const double a = s / kCorner;
      return centre - kCorner * std::cos(a) * left + kCorner * std::sin(a) * along;
    }
    s -= arc;
    start = centre + kCorner * along;
    heading += 0.5 * M_PI;
  }
  return start;
}

SE3 bodyPose(double s, const SyntheticSequenceOptions& o) {
  Vec3 p, q;  // here and a step ahead
  if (o.rounded_rectangle) {
    p = rectanglePoint(s, o.rectangle_x_m, o.rectangle_y_m);
    q = rectanglePoint(s + 1e-3, o.rectangle_x_m, o.rectangle_y_m);
  } else {
    const double a = s / o.radius_m;
    p = circlePointAt(a, o.radius_m);
    q = circlePointAt(a + 1e-3, o.radius_m);
  }
  const Vec3 forward = (q - p).normalized();
  const Vec3 down(0, 0, -1);
  const Vec3 right = down.cross(forward);  // x = y cross z
  Mat3 R;
  R.col(0) = right;
  R.col(1) = down;
  R.col(2) = forward;
  return SE3(R, p);
}
}  // namespace

// Points on a cylinder wall around the loop, on the floor and on a few pillars inside.
SyntheticSequence::Point SyntheticSequence::drawPoint(std::mt19937& rng) const {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<uint64_t> bits;
  const SyntheticSequenceOptions& o = options_;
  const double wall = o.radius_m * 1.25 + 3.0;
  Point point;
  const double kind = u(rng);
  if (kind < 0.6) {
    const double a = 2 * M_PI * u(rng);
    const double rr = wall + 2.0 * u(rng);
    point.p_w = Vec3(rr * std::cos(a), rr * std::sin(a), 3.0 * u(rng));
  } else if (kind < 0.8) {
    const double a = 2 * M_PI * u(rng);
    const double rr = o.radius_m * 0.5 * u(rng);
    point.p_w = Vec3(rr * std::cos(a), rr * std::sin(a), 2.5 * u(rng));
  } else {
    const double a = 2 * M_PI * u(rng);
    const double rr = wall * std::sqrt(u(rng));
    point.p_w = Vec3(rr * std::cos(a), rr * std::sin(a), 0.0);
  }
  for (auto& w : point.descriptor) w = bits(rng);
  // Octaves as an ORB pyramid spreads them (each level holds 1/1.2 of the one below); a point keeps its
  // octave in every view, as its image scale changes little along the sequence.
  while (point.octave < 7 && u(rng) < 1.0 / 1.2) ++point.octave;
  return point;
}

SyntheticSequence::SyntheticSequence(const Rig& rig, const SyntheticSequenceOptions& o)
    : rig_(rig), options_(o), rng_(o.seed) {
  for (int i = 0; i < o.points; ++i) points_.push_back(drawPoint(rng_));
  const double length_per_frame = o.speed_mps / o.rate_hz;
  for (int i = 0; i < o.frames; ++i) {
    StampedPose sp;
    sp.t = static_cast<Timestamp>(i * 1e9 / o.rate_hz);
    sp.T_w_b = bodyPose(i * length_per_frame, o);
    truth_.push_back(sp);
  }
}

void SyntheticSequence::fill(int i, FrameFeatures& out) {
  std::normal_distribution<double> noise(0.0, options_.noise_px);
  std::uniform_int_distribution<int> bit(0, 255);
  out.clear();
  out.t = truth_[i].t;
  const SE3& T_w_b = truth_[i].T_w_b;
  frame_points_.clear();
  // Their own generator: the world's points and rng_'s draws stay as they are without them.
  std::mt19937 frame_rng(static_cast<uint32_t>(options_.seed * 7919 + static_cast<uint64_t>(i)));
  for (int k = 0; k < options_.one_frame_points; ++k) frame_points_.push_back(drawPoint(frame_rng));
  for (int c = 0; c < rig_.size(); ++c) {
    out.present[c] = 1;
    const SE3 T_c_w = (T_w_b * rig_.T_b_c(c)).inverse();
    const CameraModel& m = rig_.model(c);
    struct Item {
      double depth;
      const Point* point;
      Vec2 uv;
    };
    std::vector<Item> items;
    for (const std::vector<Point>* set : {&points_, &frame_points_}) {
      for (const Point& point : *set) {
        const Vec3 pc = T_c_w * point.p_w;
        Vec2 uv;
        if (pc.z() < 0.2 || !m.project(pc, uv) || !m.inImage(uv, 20)) continue;
        items.push_back({pc.z(), &point, uv});
      }
    }
    // The detector keeps the best-spread features up to its budget: here the nearest ones.
    std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.depth < b.depth; });
    FeatureSet& set = out.sets[c];
    set.count = 0;
    for (const Item& it : items) {
      if (set.count == set.capacity()) break;
      Keypoint kp;
      const int octave = it.point->octave;
      const double sigma = std::pow(1.2, octave);
      kp.x = static_cast<float>(it.uv.x() + noise(rng_) * sigma);
      kp.y = static_cast<float>(it.uv.y() + noise(rng_) * sigma);
      kp.octave = static_cast<int8_t>(octave);
      Descriptor d = it.point->descriptor;
      for (int f = 0; f < 10; ++f) {
        const int b = bit(rng_);
        d[b / 64] ^= uint64_t{1} << (b % 64);
      }
      set.keypoints[set.count] = kp;
      set.descriptors[set.count] = d;
      ++set.count;
    }
  }
}

double alignedRmse(const Trajectory& truth, const Trajectory& est, bool scale, double* scale_out) {
  std::map<Timestamp, Vec3> gt;
  for (const auto& p : truth) gt[p.t] = p.T_w_b.t;
  std::vector<Vec3> a, b;
  for (const auto& p : est) {
    const auto it = gt.find(p.t);
    if (it == gt.end()) continue;
    a.push_back(p.T_w_b.t);
    b.push_back(it->second);
  }
  if (a.size() < 3) return 1e9;
  Eigen::Matrix3Xd A(3, a.size()), B(3, b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    A.col(i) = a[i];
    B.col(i) = b[i];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(A, B, scale);
  if (scale_out)
    *scale_out = T.topLeftCorner<3, 3>().determinant() > 0 ? std::cbrt(T.topLeftCorner<3, 3>().determinant()) : 0;
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Vec3 p = T.topLeftCorner<3, 3>() * a[i] + T.topRightCorner<3, 1>();
    sum += (p - b[i]).squaredNorm();
  }
  return std::sqrt(sum / a.size());
}

}  // namespace mcslam::test
