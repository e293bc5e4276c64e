// Simulator rendering speed: 720x540 images per second from the isec rig in the indoor world with the default
// render options (anti-aliasing, mip-mapped textures, sensor model) on 2 threads. Each iteration renders one image,
// cycling through the 7 cameras and through frames spread over the ground loop, so the figure averages over
// viewpoints. The world build and the camera tables are made once, before timing.
//
// SimRender/isec_720x540_1thread is the same on one thread: its CPU time per image is the renderer's cost and
// barely depends on what else runs on the machine.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "mcslam/sim/simulation.hpp"

namespace {

// Built once per thread count: Google Benchmark calls a case several times while it sizes the run.
mcslam::sim::Simulation& isecIndoor(int threads) {
  static std::map<int, std::unique_ptr<mcslam::sim::Simulation>> sims;
  auto& sim = sims[threads];
  if (!sim) {
    mcslam::sim::SimulationConfig cfg;  // isec rig, indoor world, ground robot, 10 Hz, default render options
    cfg.render.threads = threads;
    sim = std::make_unique<mcslam::sim::Simulation>(cfg);
  }
  return *sim;
}

void renderImages(benchmark::State& state, int threads) {
  mcslam::sim::Simulation& sim = isecIndoor(threads);
  const int cams = sim.rig().size(), frames = sim.frameCount();
  mcslam::Image image;
  int k = 0;
  for (auto _ : state) {
    const int cam = k % cams, frame = (k / cams * 97) % frames;  // 97: steps around the loop without repeating soon
    sim.render(frame, cam, image);
    benchmark::DoNotOptimize(image.data());
    ++k;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["width"] = image.width();
  state.counters["height"] = image.height();
}

void SimRenderIsec2Threads(benchmark::State& state) { renderImages(state, 2); }
void SimRenderIsec1Thread(benchmark::State& state) { renderImages(state, 1); }

}  // namespace

BENCHMARK(SimRenderIsec2Threads)
    ->Name("SimRender/isec_720x540")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(SimRenderIsec1Thread)->Name("SimRender/isec_720x540_1thread")->Unit(benchmark::kMillisecond)->MinTime(3.0);
