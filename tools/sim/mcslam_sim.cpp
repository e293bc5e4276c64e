// mcslam-sim: renders a multi-camera sequence with exact ground truth and writes it as an ASL dataset.
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>

#include "contact_sheet.hpp"
#include "mcslam/calib/rig.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/core/time.hpp"
#include "mcslam/sim/dataset_export.hpp"
#include "mcslam/sim/rig_presets.hpp"
#include "mcslam/sim/simulation.hpp"

using namespace mcslam;
namespace fs = std::filesystem;

namespace {

std::string footer() {
  return "\nRIG presets (or give a Kalibr camchain file):\n" + sim::describeRigPresets() + "\nWORLDs:\n" +
         sim::describeWorlds() + "\nTRAJectories:\n" + sim::describeTrajectories() +
         "\nOutput (native ASL layout, read by mcslam::Dataset):\n"
         "  DIR/camchain.yaml            the written cameras; body frame = the first written camera\n"
         "  DIR/camN/data.csv, data/     8-bit grey PNG images named <stamp ns>.png\n"
         "  DIR/camN/depth/<ns>.png      16-bit depth along the optical axis, millimetres (0 = none or > 65.5 m)\n"
         "  DIR/groundtruth.txt          TUM poses (t tx ty tz qx qy qz qw) of the body in the world, z up\n"
         "  DIR/sim.yaml                 the settings used\n"
         "\nWith no options: isec rig, indoor world, one ground-robot loop at 10 Hz, into ./mcslam_sim_out.\n"
         "With --preview FILE.png (and no --out): only a contact sheet of one frame of the selected cameras,\n"
         "labelled with their rig indices - to see what a rig sees before rendering a whole sequence.\n"
         "Same seed, same bytes (whatever --threads).\n";
}

// Removes what a previous run would have written; refuses a folder with other content.
void prepareOutput(const std::string& dir, bool overwrite) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return;
  if (!fs::is_directory(dir, ec)) throw InputError(dir + ": exists and is not a folder");
  bool empty = true;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    (void)e;
    empty = false;
    break;
  }
  if (empty) return;
  if (!overwrite) throw InputError(dir + ": output folder is not empty (use --overwrite to replace a previous run)");
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const bool ours = name == "camchain.yaml" || name == "groundtruth.txt" || name == "sim.yaml" ||
                      (name.rfind("cam", 0) == 0 && e.is_directory());
    if (ours) fs::remove_all(e.path(), ec);
  }
}

// Checks what can be checked before the (slow) world build, so mistakes are reported at once.
void validateEarly(const sim::SimulationConfig& cfg, const std::vector<int>& cameras, const std::string& preview,
                   double preview_scale, int preview_frame) {
  const Rig rig = sim::loadRig(cfg.rig);
  if (!cameras.empty()) {
    try {
      rig.subset(cameras);
    } catch (const InputError& e) {
      throw InputError(std::string("--cameras: ") + e.what());
    }
  }
  if (!(preview_scale > 0 && preview_scale <= 1)) {
    throw InputError("--preview-scale must be in (0, 1], got " + std::to_string(preview_scale));
  }
  if (preview_frame < 0) throw InputError("--preview-frame must not be negative, got " + std::to_string(preview_frame));
  if (preview.empty()) return;
  const fs::path p(preview);
  if (p.extension() != ".png" && p.extension() != ".PNG") {
    throw InputError("--preview " + preview + ": the contact sheet is a PNG, name it *.png");
  }
  std::error_code ec;
  if (p.has_parent_path() && !fs::is_directory(p.parent_path(), ec)) {
    throw InputError("--preview " + preview + ": folder " + p.parent_path().string() + " does not exist");
  }
}

// One frame of the given cameras as a contact sheet.
void writePreview(sim::Simulation& simulation, const std::vector<int>& cameras, int frame, double scale,
                  const std::string& path) {
  if (frame >= simulation.frameCount()) {
    throw InputError("--preview-frame " + std::to_string(frame) + " is beyond the last frame (" +
                     std::to_string(simulation.frameCount() - 1) + ")");
  }
  std::vector<Image> images(cameras.size());
  std::vector<sim::SheetTile> tiles;
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    simulation.render(frame, cameras[k], images[k]);
    tiles.push_back({&images[k], "cam" + std::to_string(cameras[k])});
  }
  sim::writeContactSheet(path, tiles, scale);
}

struct SimOptions {
  sim::SimulationConfig cfg;
  std::string out = "mcslam_sim_out", cameras, preview;
  double preview_scale = 0.5;
  int preview_frame = 0;
  bool no_depth = false, no_noise = false, no_exposure = false, no_vignetting = false, no_aa = false;
  bool overwrite = false, quiet = false;
  double blur_ms = 0.0;
};

void addOptions(CLI::App& app, SimOptions& o) {
  sim::SimulationConfig& cfg = o.cfg;
  app.add_option("--rig", cfg.rig, "Preset name (isec, stereo, mono, ring8) or Kalibr camchain file")
      ->capture_default_str();
  app.add_option("--world", cfg.world, "indoor, corridor or courtyard")->capture_default_str();
  app.add_option("--trajectory", cfg.trajectory, "ground, handheld or file:PATH (TUM)")->capture_default_str();
  app.add_option("--frames", cfg.frames, "Frames to render; 0 = the whole trajectory")->capture_default_str();
  app.add_option("--rate", cfg.rate_hz, "Frame rate in Hz (the motion is in physical time)")->capture_default_str();
  app.add_option("--seed", cfg.seed,
                 "Seed of the world's layout and textures, the motion's wobble and the sensor noise")
      ->capture_default_str();
  app.add_option("--out", o.out, "Output folder")->capture_default_str();
  app.add_option("--cameras", o.cameras,
                 "Cameras to write, by index, e.g. 0,2,4 (default: all); the first is the body");
  app.add_flag("--moving-objects", cfg.moving_objects, "People-sized boxes walking through the scene");
  app.add_option("--textures", cfg.textures_dir,
                 "Folder of photographs (PNG/JPG) to use instead of procedural textures");
  app.add_flag("--no-depth", o.no_depth, "Do not write depth images");
  app.add_flag("--no-noise", o.no_noise, "No sensor noise");
  app.add_flag("--no-exposure-variation", o.no_exposure, "Same gain for every camera and frame");
  app.add_flag("--no-vignetting", o.no_vignetting, "No lens vignetting");
  app.add_flag("--no-antialiasing", o.no_aa, "One ray per pixel (aliased edges; faster)");
  app.add_option("--motion-blur", o.blur_ms, "Exposure time in ms for motion blur (0 = none)")->capture_default_str();
  app.add_option("--threads", cfg.render.threads, "Render threads (0 = all cores); does not change the output")
      ->capture_default_str();
  app.add_flag("--overwrite", o.overwrite, "Replace the output of a previous run in --out");
  app.add_flag("--quiet", o.quiet, "No progress output");
  app.add_option("--preview", o.preview,
                 "Write a contact sheet (PNG) of one frame of the selected cameras; without --out, only that");
  app.add_option("--preview-frame", o.preview_frame, "Frame shown by --preview")->capture_default_str();
  app.add_option("--preview-scale", o.preview_scale,
                 "Size of each camera in the contact sheet, relative to its resolution")
      ->capture_default_str();
}

// The options into the simulation's settings and the export's. Throws InputError naming the option.
sim::ExportOptions applyOptions(SimOptions& o) {
  sim::SimulationConfig& cfg = o.cfg;
  cfg.render.sensor.noise = !o.no_noise;
  cfg.render.sensor.exposure_variation = !o.no_exposure;
  cfg.render.sensor.vignetting = !o.no_vignetting;
  cfg.render.anti_aliasing = !o.no_aa;
  if (o.blur_ms < 0) throw InputError("--motion-blur must not be negative, got " + std::to_string(o.blur_ms));
  cfg.render.sensor.motion_blur_s = o.blur_ms * 1e-3;
  if (cfg.render.threads < 0) throw InputError("--threads must not be negative");
  sim::ExportOptions options;
  if (!o.cameras.empty()) {
    try {
      options.cameras = parseCameraList(o.cameras);
    } catch (const InputError& e) {
      throw InputError(std::string("--cameras: ") + e.what());
    }
  }
  options.depth = !o.no_depth;
  return options;
}

// Renders the whole sequence into o.out.
void writeDataset(sim::Simulation& simulation, const SimOptions& o, sim::ExportOptions options, int cameras,
                  Timestamp t0) {
  const sim::SimulationConfig& cfg = o.cfg;
  if (!o.quiet) {
    std::fprintf(stderr, "mcslam-sim: %s world, %s, %d frames at %.3g Hz, %d cameras -> %s\n", cfg.world.c_str(),
                 simulation.trajectory().description().c_str(), simulation.frameCount(), cfg.rate_hz, cameras,
                 o.out.c_str());
  }
  const bool tty = isatty(fileno(stderr));
  options.description = "mcslam-sim --rig " + cfg.rig + " --world " + cfg.world + " --trajectory " + cfg.trajectory;
  if (!o.quiet) {
    options.progress = [tty](int done, int total) {
      if (tty)
        std::fprintf(stderr, "\r  frame %d/%d", done, total);
      else if (done % 100 == 0 || done == total)
        std::fprintf(stderr, "  frame %d/%d\n", done, total);
      if (tty && done == total) std::fprintf(stderr, "\n");
    };
  }
  const sim::ExportSummary s = sim::exportDataset(simulation, o.out, options);
  if (!o.quiet) {
    std::fprintf(stderr, "mcslam-sim: wrote %d frames x %d cameras (%.1f m in %.1f s of motion) in %.1f s\n", s.frames,
                 s.cameras, s.path_length, s.duration, toSeconds(monotonicNowNs() - t0));
  }
}

void run(SimOptions& o, bool write_dataset) {
  const sim::ExportOptions options = applyOptions(o);
  validateEarly(o.cfg, options.cameras, o.preview, o.preview_scale, o.preview_frame);
  if (write_dataset) prepareOutput(o.out, o.overwrite);
  const Timestamp t0 = monotonicNowNs();
  sim::Simulation simulation(o.cfg);
  std::vector<int> selected = options.cameras;
  if (selected.empty()) {
    for (int c = 0; c < simulation.rig().size(); ++c) selected.push_back(c);
  }
  if (!o.preview.empty()) {
    writePreview(simulation, selected, o.preview_frame, o.preview_scale, o.preview);
    if (!o.quiet) std::fprintf(stderr, "mcslam-sim: wrote %s (frame %d)\n", o.preview.c_str(), o.preview_frame);
  }
  if (write_dataset) writeDataset(simulation, o, options, static_cast<int>(selected.size()), t0);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-sim: render a multi-camera sequence with exact ground truth (ASL dataset + depth)"};
  app.footer(footer());
  SimOptions options;
  addOptions(app, options);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "mcslam-sim: %s (see --help)\n", e.what());
    return 2;
  }
  try {
    run(options, options.preview.empty() || app.count("--out") > 0);
  } catch (const InputError& e) {
    std::fprintf(stderr, "mcslam-sim: %s\n", e.what());
    return 2;
  }
  return 0;
}
