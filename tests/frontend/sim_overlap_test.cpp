// The overlap map of the isec and ring8 presets against the true overlap of rendered scenes: every pixel with a
// rendered depth in the configured range is back-projected and projected into every other camera; where it
// lands inside that image the map must list the cell (no true match is ever out of reach), and the cells of
// camera i that see something of camera j must be the ones the map says overlap.
#include <gtest/gtest.h>

#include <cstdio>

#include "mcslam/features/overlap_map.hpp"
#include "sim_frames.hpp"

using namespace mcslam;

namespace {

struct PairTruth {
  int samples = 0;             // pixels of i whose point lands inside image j
  int listed = 0;              // of which the landing cell is a candidate of the pixel's cell
  std::vector<uint8_t> cells;  // cells of i with true overlap
};

// True overlap of camera i with camera j from i's depth image (every `step`-th pixel).
PairTruth trueOverlap(const Rig& rig, const OverlapMap& map, const sim::DepthImage& depth, int i, int j, int step) {
  const CameraModel& mi = rig.model(i);
  const CameraModel& mj = rig.model(j);
  const SE3 T_j_i = rig.T_b_c(j).inverse() * rig.T_b_c(i);
  const OverlapOptions& o = map.options();
  PairTruth t;
  t.cells.assign(map.grid(i).cells(), 0);
  for (int y = 0; y < depth.height; y += step) {
    for (int x = 0; x < depth.width; x += step) {
      const double z = depth.at(x, y);
      Vec3 bearing;
      if (!(z > 0) || !mi.unproject(Vec2(x, y), bearing) || !(bearing.z() > 1e-3)) continue;
      const Vec3 p_i = bearing * (z / bearing.z());
      if (p_i.norm() < o.min_depth || p_i.norm() > o.max_depth) continue;
      Vec2 uv;
      const Vec3 p_j = T_j_i * p_i;
      if (p_j.z() <= 0 || !mj.project(p_j, uv)) continue;
      const int cj = map.grid(j).cellOf(uv.x(), uv.y());
      if (cj < 0) continue;
      const int ci = map.grid(i).cellOf(x, y);
      ++t.samples;
      t.cells[ci] = 1;
      const auto cand = map.candidates(i, j, ci);
      t.listed += std::find(cand.begin(), cand.end(), cj) != cand.end() ? 1 : 0;
    }
  }
  return t;
}

// Checks every ordered pair of cameras of `rig_name` on rendered frames of the indoor world.
void checkPreset(const std::string& rig_name, const std::vector<int>& frames) {
  sim::Simulation& sim = test::sharedSimulation(rig_name, "indoor");
  const Rig& rig = sim.rig();
  const OverlapMap map(rig, OverlapOptions{});
  const int n = rig.size();
  std::vector<int> all(n);
  for (int c = 0; c < n; ++c) all[c] = c;
  std::vector<PairTruth> truth(n * n);
  for (const int frame : frames) {
    const test::RenderedFrame f = test::renderFrame(sim, frame, all);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        if (i == j) continue;
        const PairTruth t = trueOverlap(rig, map, f.depths[i], i, j, 4);
        PairTruth& sum = truth[i * n + j];
        if (sum.cells.empty()) sum.cells.assign(t.cells.size(), 0);
        sum.samples += t.samples;
        sum.listed += t.listed;
        for (std::size_t c = 0; c < t.cells.size(); ++c) sum.cells[c] |= t.cells[c];
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      const PairTruth& t = truth[i * n + j];
      int true_cells = 0, missed_cells = 0;
      for (int c = 0; c < map.grid(i).cells(); ++c) {
        if (!t.cells[c]) continue;
        ++true_cells;
        missed_cells += map.candidates(i, j, c).empty() ? 1 : 0;
      }
      std::printf("%s %d->%d: true cells %d (map %.0f%%), missed %d, samples %d listed %.4f\n", rig_name.c_str(), i, j,
                  true_cells, 100.0 * map.overlapFraction(i, j), missed_cells, t.samples,
                  t.samples ? static_cast<double>(t.listed) / t.samples : 1.0);
      if (true_cells == 0) {
        // No rendered overlap: the map may still list some (scenes at other depths), but only a little.
        EXPECT_LT(map.overlapFraction(i, j), 0.1) << rig_name << " " << i << "->" << j;
        continue;
      }
      EXPECT_TRUE(map.overlaps(i, j)) << rig_name << " " << i << "->" << j;
      EXPECT_LE(missed_cells, std::max(1, true_cells / 100)) << rig_name << " " << i << "->" << j;
      EXPECT_GE(t.listed, 0.999 * t.samples) << rig_name << " " << i << "->" << j;
      // The map's overlap is the geometric one over the depth range: a superset of one scene's, not the image.
      EXPECT_LE(true_cells, static_cast<int>(map.overlapFraction(i, j) * map.grid(i).cells()) + 1);
    }
  }
}

}  // namespace

TEST(SimOverlap, IsecPresetMapCoversTheRenderedOverlap) {
  const int n = test::sharedSimulation("isec", "indoor").frameCount();
  checkPreset("isec", {0, n / 3, 2 * n / 3});
}

TEST(SimOverlap, Ring8PresetMapCoversTheRenderedOverlap) {
  const int n = test::sharedSimulation("ring8", "indoor").frameCount();
  checkPreset("ring8", {0, n / 2});
}
