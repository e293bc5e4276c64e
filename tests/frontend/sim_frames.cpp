#include "sim_frames.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <utility>

#include "mcslam/pipeline/front_end.hpp"

namespace mcslam::test {

sim::Simulation& sharedSimulation(const std::string& rig, const std::string& world) {
  static std::map<std::pair<std::string, std::string>, std::unique_ptr<sim::Simulation>> cache;
  auto& slot = cache[{rig, world}];
  if (!slot) {
    sim::SimulationConfig cfg;
    cfg.rig = rig;
    cfg.world = world;
    cfg.seed = 1;
    slot = std::make_unique<sim::Simulation>(cfg);
  }
  return *slot;
}

RigFrameView RenderedFrame::view() const {
  RigFrameView v;
  v.cameras = static_cast<int>(views.size());
  v.images = views.data();
  v.present = present.get();
  return v;
}

RenderedFrame renderFrame(sim::Simulation& sim, int frame, const std::vector<int>& cameras) {
  const int n = sim.rig().size();
  RenderedFrame f;
  f.images.resize(n);
  f.depths.resize(n);
  f.views.resize(n);
  f.present.reset(new bool[n]());
  for (const int c : cameras) {
    sim.render(frame, c, f.images[c], &f.depths[c]);
    f.views[c] = f.images[c].view();
    f.present[c] = true;
  }
  return f;
}

double depthAt(const sim::DepthImage& depth, double x, double y) {
  const int px = static_cast<int>(std::lround(x)), py = static_cast<int>(std::lround(y));
  if (px < 0 || py < 0 || px >= depth.width || py >= depth.height) return 0.0;
  return depth.at(px, py);
}

// Truth at a keypoint: the depth at its pixel, or on a depth discontinuity the depth within the keypoint's
// rounding (2 pixels of its octave) nearest to the estimate: a corner on a silhouette belongs to the object in
// front, but which pixel holds it is a matter of rounding. A discontinuity is where the inverse depth is not
// locally affine in the image (a plane's inverse depth is, up to the lens distortion's curvature): a second
// difference above 0.5% of it, far below the 2% tolerance and far above the curvature. (Before, a window
// spanning more than 5% counted as an edge: that missed steps of 2-5%, which the 2% tolerance resolves, and
// counted steep planes such as the floor near the horizon as edges.)
double trueDepth(const sim::DepthImage& depth, double x, double y, int octave, double estimate, bool* edge) {
  const double centre = depthAt(depth, x, y);
  if (!(centre > 0)) return centre;
  const int r = static_cast<int>(std::lround(2 * std::pow(1.2, octave)));
  auto inverse = [&](int dx, int dy) {
    const double d = depthAt(depth, x + dx, y + dy);
    return d > 0 ? 1.0 / d : 0.0;
  };
  const double bound = 0.005 / centre;
  bool discontinuity = false;
  double nearest = centre;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const double d = depthAt(depth, x + dx, y + dy);
      if (!(d > 0)) {
        discontinuity = true;  // nothing rendered there: sky beyond a silhouette
        continue;
      }
      if (std::abs(d - estimate) < std::abs(nearest - estimate)) nearest = d;
      const double inv = inverse(dx, dy);
      if (dx > -r && dx < r && std::abs(inverse(dx - 1, dy) - 2 * inv + inverse(dx + 1, dy)) > bound)
        discontinuity = true;
      if (dy > -r && dy < r && std::abs(inverse(dx, dy - 1) - 2 * inv + inverse(dx, dy + 1)) > bound)
        discontinuity = true;
    }
  }
  if (edge != nullptr) *edge = discontinuity;
  return discontinuity ? nearest : centre;
}

void forEachFrontCameraDepth(sim::Simulation& sim, const PipelineConfig& config, int frame, double max_sigma,
                             const std::function<void(const MultiViewFeature& mv, double error, bool edge)>& visit) {
  const std::vector<int> front = {0, 1, 2, 3, 4};
  const Rig rig = sim.rig().subset(front);  // keeps the body frame: camera c here is camera c of the preset
  FrontEnd front_end(rig, config);
  const RenderedFrame rendered = renderFrame(sim, frame, front);
  RigFrameView view = rendered.view();
  view.cameras = rig.size();
  FrameFeatures f(rig.size(), front_end.capacityPerCamera());
  front_end.compute(view, f);
  for (int t = 0; t < f.mv_count; ++t) {
    const MultiViewFeature& mv = f.mv[t];
    if (!mv.has_point || mv.relative_depth_sigma > max_sigma) continue;
    const KeypointRef& ref = f.mv_refs[mv.first];
    const Keypoint& kp = f.sets[ref.cam].keypoints[ref.index];
    const double z = (rig.T_b_c(ref.cam).inverse() * mv.p_b).z();
    bool edge = false;
    const double truth = trueDepth(rendered.depths[ref.cam], kp.x, kp.y, kp.octave, z, &edge);
    if (!(truth > 0)) continue;  // nothing rendered there
    visit(mv, std::abs(z - truth) / truth, edge);
  }
}

}  // namespace mcslam::test
