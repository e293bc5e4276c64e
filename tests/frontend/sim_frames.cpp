#include "sim_frames.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <utility>

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

}  // namespace mcslam::test
