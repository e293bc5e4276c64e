// mcslam-dataset: what a dataset folder holds (layout, cameras, frames, ground truth), and conversion between
// the layouts mcslam reads (native ASL, EuRoC, KITTI) - e.g. to replay a rendered sequence in another system.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "mcslam/core/error.hpp"
#include "mcslam/core/json_writer.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/dataset_export.hpp"

using namespace mcslam;

namespace {

struct Summary {
  std::size_t complete = 0;  // rig frames with every camera
  double duration_s = 0, rate_hz = 0;
};

Summary summarize(const Dataset& ds) {
  Summary s;
  for (const RigFrameEntry& f : ds.frames()) {
    bool all = true;
    for (const std::string& p : f.image_paths) all = all && !p.empty();
    s.complete += all ? 1 : 0;
  }
  if (ds.size() >= 2) {
    s.duration_s = toSeconds(ds.frames().back().t - ds.frames().front().t);
    s.rate_hz = s.duration_s > 0 ? static_cast<double>(ds.size() - 1) / s.duration_s : 0.0;
  }
  return s;
}

void printInfoText(const Dataset& ds) {
  const Summary s = summarize(ds);
  std::printf("%s: %s layout, %d camera%s\n", ds.directory().c_str(), ds.format().c_str(), ds.rig().size(),
              ds.rig().size() == 1 ? "" : "s");
  for (int c = 0; c < ds.rig().size(); ++c) {
    const CameraModel& m = ds.rig().model(c);
    std::printf("  %-6s %4dx%-4d pinhole/%s\n", ds.rig().cameras[c].name.c_str(), m.width(), m.height(),
                distortionName(m.distortion()));
  }
  std::printf("rig frames: %zu (%zu with every camera), %.2f s, %.2f Hz; sync tolerance %.3f ms\n", ds.size(),
              s.complete, s.duration_s, s.rate_hz, static_cast<double>(ds.syncToleranceNs()) * 1e-6);
  if (ds.groundTruth()) {
    std::printf("ground truth: %zu poses, %.2f m of path (%s)\n", ds.groundTruth()->size(),
                pathLength(*ds.groundTruth()), ds.groundTruthPath().c_str());
  } else {
    std::printf("ground truth: none\n");
  }
  for (const std::string& w : ds.warnings()) std::printf("warning: %s\n", w.c_str());
}

void printInfoJson(const Dataset& ds) {
  const Summary s = summarize(ds);
  JsonWriter j(std::cout);
  j.beginObject();
  j.key("folder").value(ds.directory());
  j.key("layout").value(ds.format());
  j.key("cameras").beginArray();
  for (int c = 0; c < ds.rig().size(); ++c) {
    const CameraModel& m = ds.rig().model(c);
    j.beginObject();
    j.key("name").value(ds.rig().cameras[c].name);
    j.key("resolution").beginArray().value(m.width()).value(m.height()).endArray();
    j.key("distortion").value(distortionName(m.distortion()));
    j.endObject();
  }
  j.endArray();
  j.key("rig_frames").value(ds.size());
  j.key("complete_rig_frames").value(s.complete);
  j.key("duration_s").value(s.duration_s);
  j.key("rate_hz").value(s.rate_hz);
  j.key("ground_truth_poses").value(ds.groundTruth() ? ds.groundTruth()->size() : std::size_t{0});
  j.key("ground_truth_path_m").value(ds.groundTruth() ? pathLength(*ds.groundTruth()) : 0.0);
  j.key("warnings").beginArray();
  for (const std::string& w : ds.warnings()) j.value(w);
  j.endArray();
  j.endObject();
  std::cout << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-dataset: inspect a dataset folder or write it in another layout"};
  app.require_subcommand(1);
  std::string dir, cameras;
  bool json = false;
  auto* info = app.add_subcommand("info", "Layout, cameras, rig frames, rate and ground truth of a dataset folder");
  info->add_option("DATASET", dir, "Dataset folder (native ASL, EuRoC mav0/, KITTI sequence or KITTI raw drive)")
      ->required();
  info->add_flag("--json", json,
                 "Print JSON (keys: folder, layout, cameras, rig_frames, complete_rig_frames, duration_s, "
                 "rate_hz, ground_truth_poses, ground_truth_path_m, warnings)");
  info->add_option("--cameras", cameras, "Only these cameras, by calibration index, e.g. 0,1");

  std::string layout, out, images = "original";
  auto* convert = app.add_subcommand(
      "convert",
      "Write the dataset in another layout: asl (camchain.yaml, camN/), euroc (mav0/, sensor.yaml per camera, IMU or "
      "cam0 as body) or kitti (rectified cameras only: image_N/, calib.txt, times.txt, poses.txt). Images are "
      "hard-linked (or copied), never re-encoded except non-PNG images for KITTI, unless --images pgm.");
  convert->add_option("DATASET", dir, "Dataset folder to read (any layout)")->required();
  convert->add_option("--layout", layout, "asl, euroc or kitti")->required();
  convert->add_option("--out", out, "Output folder (must not exist or be empty)")->required();
  convert->add_option("--cameras", cameras,
                      "Write only these cameras, by calibration index, e.g. 1,2 (the first "
                      "becomes the written cam0)");
  convert
      ->add_option("--images", images,
                   "original (hard links of the files) or pgm (every image written as binary 8-bit PGM, asl and "
                   "euroc only: a replay that needs no image codec, e.g. for mcslamd)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    DatasetOptions options;
    if (!cameras.empty()) options.cameras = parseCameraList(cameras);
    if (convert->parsed()) {
      const DatasetLayoutKind kind = parseDatasetLayout(layout);  // before the (slower) indexing of the input
      DatasetExportOptions export_options;
      export_options.images = parseExportImages(images);
      const Dataset ds = Dataset::open(dir, options);
      for (const std::string& w : ds.warnings()) std::fprintf(stderr, "mcslam-dataset: warning: %s\n", w.c_str());
      const DatasetExportReport r = exportDataset(ds, kind, out, export_options);
      for (const std::string& w : r.warnings) std::fprintf(stderr, "mcslam-dataset: warning: %s\n", w.c_str());
      std::printf("%s (%s) -> %s (%s): %zu rig frames, %zu images, %zu ground-truth poses\n", dir.c_str(),
                  ds.format().c_str(), out.c_str(), datasetLayoutName(kind), r.frames_written, r.images_written,
                  r.ground_truth_poses);
    } else {
      const Dataset ds = Dataset::open(dir, options);
      if (json)
        printInfoJson(ds);
      else
        printInfoText(ds);
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "mcslam-dataset: %s\n", e.what());
    return 2;
  }
  return 0;
}
