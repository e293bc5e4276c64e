// The dataset readers of text files (dataset/, trajectory.hpp): the input's first byte picks the file it becomes
// (byte % 6: 0 TUM trajectory, 1 times.txt, 2 KITTI poses, 3 an ASL camN/data.csv, 4 EuRoC ground truth CSV,
// 5 KITTI calib.txt), the rest is its content, read through the dataset's own reader. An image list also goes
// through the rig frame assembly. Documented outcome for bad input: InputError.
#include <cstdint>
#include <string>
#include <vector>

#include "dataset_layout.hpp"
#include "fuzz_support.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/image_file.hpp"
#include "mcslam/dataset/rig_frame_sync.hpp"
#include "mcslam/dataset/trajectory.hpp"

namespace {

using mcslam::fuzz::tempFolder;

// The fixed files around the fuzzed one: a KITTI sequence (one 4x3 image, three times), ASL images.
struct Fixture {
  std::string kitti, times, asl_camera, mav0;
  mcslam::Rig rig;
  Fixture() {
    const auto& tmp = tempFolder();
    times = tmp.write("kitti/times.txt", "0.0\n0.1\n0.2\n");
    tmp.write("kitti/image_0/000000.png", std::string("P5 4 3 255\n") + std::string(12, '\x80'));
    kitti = tmp.dir() + "/kitti";
    tmp.write("asl/cam0/data/1403636579763555584.png", "");
    tmp.write("asl/cam0/data/1403636579813555456.png", "");
    asl_camera = tmp.dir() + "/asl/cam0";
    mav0 = tmp.dir() + "/mav0";
    mcslam::RigCamera c;
    c.name = "cam0";
    rig.cameras.push_back(c);
    rig.T_b_imu = mcslam::SE3();
  }
};

void assemble(const std::vector<mcslam::CameraImage>& images) {
  std::vector<mcslam::CameraImage> shifted = images;
  for (mcslam::CameraImage& image : shifted) image.t += 1000;
  const std::vector<std::vector<mcslam::CameraImage>> cameras{images, shifted};
  (void)mcslam::assembleRigFrames(cameras, mcslam::automaticSyncTolerance(cameras));
}

void readAs(int kind, const std::string& content, const Fixture& f) {
  const auto& tmp = tempFolder();
  std::vector<std::string> warnings;
  switch (kind) {
    case 0: (void)mcslam::parseTumTrajectory(content, "groundtruth.txt"); break;
    case 1: (void)mcslam::readTimesFile(tmp.write("times.txt", content)); break;
    case 2: (void)mcslam::readKittiTrajectory(tmp.write("poses.txt", content), f.times); break;
    case 3:
      tmp.write("asl/cam0/data.csv", content);
      assemble(mcslam::detail::readAslImageList(f.asl_camera, warnings));
      break;
    case 4:
      (void)mcslam::detail::makeEurocLayout(f.mav0)->readGroundTruthFile(tmp.write("gt.csv", content), f.rig);
      break;
    default:
      tmp.write("kitti/calib.txt", content);
      (void)mcslam::detail::makeKittiLayout(f.kitti)->loadRig();
      break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static const Fixture fixture;
  if (size == 0) return 0;
  try {
    readAs(data[0] % 6, mcslam::fuzz::text(data + 1, size - 1), fixture);
  } catch (const mcslam::InputError&) {
  }
  return 0;
}
