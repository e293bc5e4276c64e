#pragma once
// A rendered simulator dataset for the daemon tests and benchmarks with the real pipeline: the ISEC rig's
// five overlapping front cameras in the indoor world, ground robot, seed 1, written with exportDataset
// (camchain.yaml, images, groundtruth.txt). Rendering costs seconds, so it is cached under the build
// tree (test::cachedFolder). The name carries the build time of the simulator library, so a rebuilt renderer never
// meets images of an older one.
#include <filesystem>
#include <string>

#include "mcslam/sim/dataset_export.hpp"
#include "mcslam/sim/simulation.hpp"
#include "test_support.hpp"

namespace mcslam::test {

inline constexpr int kSimDatasetFrames = 50;

inline std::string cachedSimDataset(int frames = kSimDatasetFrames, double rate_hz = 10) {
  namespace fs = std::filesystem;
  const fs::path build = fs::path(binPath("mcslamd")).parent_path().parent_path();
  std::error_code ec;
  const auto renderer_built = fs::last_write_time(build / "lib" / "libmcslam_sim.a", ec);
  const std::string name = "daemon-isec5-indoor-ground-" + std::to_string(frames) + "-at-" +
                           std::to_string(static_cast<int>(rate_hz * 1000)) + "mHz-sim" +
                           (ec ? std::string("unknown") : std::to_string(renderer_built.time_since_epoch().count()));
  return cachedFolder(name, [&](const std::string& folder) {
    sim::SimulationConfig cfg;  // isec, indoor, ground, seed 1
    cfg.frames = frames;
    cfg.rate_hz = rate_hz;
    sim::Simulation simulation(cfg);
    sim::ExportOptions options;
    options.cameras = {0, 1, 2, 3, 4};
    options.depth = false;
    sim::exportDataset(simulation, folder, options);
    return true;
  });
}

}  // namespace mcslam::test
