#include "map_top_view.hpp"

#include <Eigen/Eigenvalues>
#include <unordered_map>

#include "mcslam/eval/map_plot.hpp"

namespace mcslam::map_tool {

namespace {

// The keyframes lie in a plane when its normal's spread is under this share of the next (standard deviations):
// a robot on a floor or a road. Below it the path is too round (a hand-held rig) or too straight to say.
constexpr double kPlaneShare = 0.5;
constexpr double kLineShare = 0.1;

// `up` as given, `h` the direction nearest `h_guess` across it.
TopView viewWithUp(const Vec3& up, const Vec3& h_guess, std::string how) {
  TopView view;
  view.up = up.normalized();
  Vec3 h = h_guess - h_guess.dot(view.up) * view.up;
  if (h.norm() < 1e-6) h = view.up.unitOrthogonal();
  view.h = h.normalized();
  view.v = view.up.cross(view.h);
  view.how = std::move(how);
  return view;
}

std::string counted(long long n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

}  // namespace

TopView topViewOf(const PlaceMap& map) {
  Vec3 mean = Vec3::Zero();
  for (int slot = 0; slot < map.size(); ++slot) mean += map.keyframe(slot).T_w_k.t;
  mean /= std::max(1, map.size());
  Mat3 scatter = Mat3::Zero();
  for (int slot = 0; slot < map.size(); ++slot) {
    const Vec3 d = map.keyframe(slot).T_w_k.t - mean;
    scatter += d * d.transpose();
  }
  const Vec3 down = map.size() > 0 ? Vec3(map.keyframe(0).T_w_k.R.col(1)) : Vec3::UnitY();
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter);
  const Vec3 spread = eigen.eigenvalues().cwiseMax(0).cwiseSqrt();  // increasing
  Vec3 main = eigen.eigenvectors().col(2);
  if (map.size() > 1 && main.dot(map.keyframe(map.size() - 1).T_w_k.t - map.keyframe(0).T_w_k.t) < 0) main = -main;
  const bool planar = spread[2] > 0 && spread[1] >= kLineShare * spread[2] && spread[0] <= kPlaneShare * spread[1];
  if (!planar) return viewWithUp(-down, main, "top view: up is against the first keyframe's y axis");
  const Vec3 normal = eigen.eigenvectors().col(0);
  return viewWithUp(normal.dot(down) > 0 ? -normal : normal, main, "top view: the plane of the keyframes' motion");
}

void plotMap(const MapContents& c, const std::string& file, const std::string& png) {
  const PlaceMap& map = *c.map;
  const TopView view = topViewOf(map);
  const auto flat = [&](const Vec3& p) { return Eigen::Vector2d(view.h.dot(p), view.v.dot(p)); };
  MapPlot plot;
  plot.paths.resize(static_cast<std::size_t>(map.segments()));
  std::unordered_map<int64_t, int> slot_of_id;
  for (int slot = 0; slot < map.size(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    slot_of_id[k.id] = slot;
    for (const PlacePoint& p : map.points(slot)) plot.points.push_back(flat(k.T_w_k * p.p_k.cast<double>()));
    if (k.previous >= 0) continue;  // walk each segment's chain from its oldest keyframe
    for (int s = slot; s >= 0; s = map.keyframe(s).next)
      plot.paths[static_cast<std::size_t>(k.segment)].keyframes.push_back(flat(map.keyframe(s).T_w_k.t));
  }
  for (std::size_t s = 0; s < plot.paths.size(); ++s) {
    const std::size_t n = plot.paths[s].keyframes.size();
    plot.paths[s].label = "segment " + std::to_string(s) + ": " + std::to_string(n) + " keyframes" +
                          (map.placed(static_cast<int32_t>(s)) ? "" : ", not placed");
  }
  for (const LoopEdge& e : c.loops) {
    const auto a = slot_of_id.find(e.a), b = slot_of_id.find(e.b);
    if (a == slot_of_id.end() || b == slot_of_id.end()) continue;  // a keyframe culled since
    plot.loops.emplace_back(flat(map.keyframe(a->second).T_w_k.t), flat(map.keyframe(b->second).T_w_k.t));
  }
  plot.title = counted(map.size(), "keyframe") + " in " + counted(map.segments(), "segment") + ", " +
               counted(static_cast<long long>(c.loops.size()), "loop") + ", " +
               counted(static_cast<long long>(plot.points.size()), "point");
  plot.subtitle = file + " - " + view.how;
  plot.h_caption = "along the path's main direction [m]";
  plot.v_caption = "across it [m]";
  writeMapPlot(png, plot);
}

}  // namespace mcslam::map_tool
