// Export into the three layouts, checked by reading the output back with our own readers: the same rig,
// frames, images and ground truth must come out (a round trip through each layout). With PGM images (the convert
// command's --images pgm) the pixels must come out unchanged.
#include <gtest/gtest.h>

#include <filesystem>

#include "dataset_test_util.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/dataset_export.hpp"

using namespace mcslam;
namespace fs = std::filesystem;

namespace {

constexpr int kFrames = 5;

SE3 groundTruthPose(int i) {
  return SE3(Eigen::AngleAxisd(0.1 * i, Vec3(0.2, 0.3, 1).normalized()).toRotationMatrix(),
             Vec3(0.5 * i, -0.2 * i, 0.05));
}

// An ASL dataset of `rig` with kFrames rig frames at 10 Hz (camera c's image of frame i has value 10 i + c) and
// ground truth at every frame; `skip_camera` of frame 2 is left out when >= 0.
std::string writeAsl(const test::TempDir& dir, const Rig& rig, int skip_camera = -1) {
  const std::string root = (dir.path() / "asl").string();
  AslDatasetWriter w(root, rig);
  Trajectory gt;
  for (int i = 0; i < kFrames; ++i) {
    const Timestamp t = 1000000000 + i * 100000000LL;
    for (int c = 0; c < rig.size(); ++c) {
      if (i == 2 && c == skip_camera) continue;
      w.writeImage(c, t, test::FlatImage(static_cast<uint8_t>(10 * i + c)).image.view());
    }
    gt.push_back({t, groundTruthPose(i)});
  }
  w.writeGroundTruth(gt);
  w.close();
  return root;
}

// The message of the InputError the export throws (empty, and a failure, when it accepts the data).
std::string exportError(const Dataset& dataset, DatasetLayoutKind layout, const std::string& out,
                        const DatasetExportOptions& options = {}) {
  try {
    exportDataset(dataset, layout, out, options);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "the export into " << out << " was accepted";
  return "";
}

void expectSamePose(const SE3& a, const SE3& b, double tol) {
  EXPECT_LT((a.t - b.t).norm(), tol);
  EXPECT_LT(Eigen::AngleAxisd(a.R.transpose() * b.R).angle(), tol);
}

// Same cameras (intrinsics and poses in the body frame), same frames and image bytes, same ground truth.
void expectSameDataset(const Dataset& a, const Dataset& b, double tol) {
  ASSERT_EQ(a.rig().size(), b.rig().size());
  for (int c = 0; c < a.rig().size(); ++c) {
    EXPECT_NEAR(a.rig().model(c).fx(), b.rig().model(c).fx(), tol);
    EXPECT_NEAR(a.rig().model(c).cy(), b.rig().model(c).cy(), tol);
    EXPECT_EQ(a.rig().model(c).width(), b.rig().model(c).width());
    expectSamePose(a.rig().T_b_c(c), b.rig().T_b_c(c), tol);
  }
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int c = 0; c < a.rig().size(); ++c) {
      ASSERT_EQ(a.frames()[i].image_paths[c].empty(), b.frames()[i].image_paths[c].empty()) << "frame " << i;
      if (a.frames()[i].image_paths[c].empty()) continue;
      EXPECT_EQ(test::readFile(a.frames()[i].image_paths[c]), test::readFile(b.frames()[i].image_paths[c]))
          << "frame " << i;
    }
  }
  ASSERT_TRUE(a.groundTruth() && b.groundTruth());
  ASSERT_EQ(a.groundTruth()->size(), b.groundTruth()->size());
  for (std::size_t i = 0; i < a.groundTruth()->size(); ++i) {
    EXPECT_EQ((*a.groundTruth())[i].t, (*b.groundTruth())[i].t);
    expectSamePose((*a.groundTruth())[i].T_w_b, (*b.groundTruth())[i].T_w_b, tol);
  }
}

}  // namespace

TEST(DatasetExport, EurocRoundTripKeepsRigFramesImagesAndGroundTruth) {
  test::TempDir dir("export_euroc");
  Rig rig = test::smallRig(3);
  rig.cameras[2].T_b_c = SE3(Eigen::AngleAxisd(0.3, Vec3::UnitY()).toRotationMatrix(), Vec3(0.2, 0.01, -0.03));
  rig.T_b_imu = SE3(Eigen::AngleAxisd(1.2, Vec3::UnitX()).toRotationMatrix(), Vec3(0.05, -0.1, 0.02));
  const Dataset asl = Dataset::open(writeAsl(dir, rig));
  const DatasetExportReport r = exportDataset(asl, DatasetLayoutKind::Euroc, dir.file("euroc"));
  EXPECT_EQ(r.frames_written, static_cast<std::size_t>(kFrames));
  EXPECT_EQ(r.images_written, static_cast<std::size_t>(3 * kFrames));
  EXPECT_EQ(r.ground_truth_poses, static_cast<std::size_t>(kFrames));
  const Dataset euroc = Dataset::open(dir.file("euroc"));
  EXPECT_EQ(euroc.format(), "euroc");
  expectSameDataset(asl, euroc, 1e-8);
  // The IMU is EuRoC's body: ground truth went through T_BS and came back.
  ASSERT_TRUE(euroc.rig().T_b_imu);
  expectSamePose(*euroc.rig().T_b_imu, *rig.T_b_imu, 1e-8);
}

TEST(DatasetExport, AslRoundTripOfACameraSubsetMovesTheBodyToItsFirstCamera) {
  test::TempDir dir("export_asl");
  const Rig rig = test::smallRig(3);
  const std::string src = writeAsl(dir, rig);
  DatasetOptions subset;
  subset.cameras = {1, 2};
  const Dataset in = Dataset::open(src, subset);
  exportDataset(in, DatasetLayoutKind::Asl, dir.file("asl_out"));
  const Dataset out = Dataset::open(dir.file("asl_out"));
  ASSERT_EQ(out.rig().size(), 2);
  // The written cam0 is the source's cam1, and it is the body now.
  expectSamePose(out.rig().T_b_c(0), SE3(), 1e-12);
  expectSamePose(out.rig().T_b_c(1), SE3(Mat3::Identity(), Vec3(0.1, 0, 0)), 1e-12);
  EXPECT_EQ(test::readFile(in.frames()[3].image_paths[1]), test::readFile(out.frames()[3].image_paths[1]));
  // Ground truth follows the body: T_w_b' = T_w_b * T_b_cam1.
  ASSERT_TRUE(out.groundTruth());
  expectSamePose((*out.groundTruth())[3].T_w_b, groundTruthPose(3) * rig.T_b_c(1), 1e-9);
}

TEST(DatasetExport, KittiRoundTripOfARectifiedRig) {
  test::TempDir dir("export_kitti");
  const Dataset asl = Dataset::open(writeAsl(dir, test::smallRig(2)));
  const DatasetExportReport r = exportDataset(asl, DatasetLayoutKind::Kitti, dir.file("kitti"));
  EXPECT_EQ(r.frames_written, static_cast<std::size_t>(kFrames));
  EXPECT_TRUE(r.warnings.empty());
  const Dataset kitti = Dataset::open(dir.file("kitti"));
  EXPECT_EQ(kitti.format(), "kitti");
  ASSERT_EQ(kitti.rig().size(), 2);
  expectSamePose(kitti.rig().T_b_c(1), SE3(Mat3::Identity(), Vec3(0.1, 0, 0)), 1e-9);
  ASSERT_EQ(kitti.size(), asl.size());
  for (std::size_t i = 0; i < kitti.size(); ++i) {
    EXPECT_EQ(kitti.frames()[i].t, asl.frames()[i].t);  // times.txt keeps the stamps to the nanosecond
    EXPECT_EQ(test::readFile(kitti.frames()[i].image_paths[1]), test::readFile(asl.frames()[i].image_paths[1]));
  }
  // KITTI poses start at the identity; relative motion is unchanged.
  ASSERT_TRUE(kitti.groundTruth());
  expectSamePose((*kitti.groundTruth())[0].T_w_b, SE3(), 1e-9);
  expectSamePose((*kitti.groundTruth())[4].T_w_b, groundTruthPose(0).inverse() * groundTruthPose(4), 1e-8);
}

TEST(DatasetExport, KittiLeavesOutRigFramesWithAMissingImageAndSaysSo) {
  test::TempDir dir("export_kitti_gap");
  const Dataset asl = Dataset::open(writeAsl(dir, test::smallRig(2), /*skip_camera=*/1));
  const DatasetExportReport r = exportDataset(asl, DatasetLayoutKind::Kitti, dir.file("kitti"));
  EXPECT_EQ(r.frames_written, static_cast<std::size_t>(kFrames - 1));
  EXPECT_EQ(r.frames_skipped, 1u);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("no image"), std::string::npos) << r.warnings[0];
  EXPECT_EQ(Dataset::open(dir.file("kitti")).size(), static_cast<std::size_t>(kFrames - 1));
}

TEST(DatasetExport, KittiRefusesDistortedOrTurnedCamerasBeforeWritingAnything) {
  test::TempDir dir("export_kitti_bad");
  Rig distorted = test::smallRig(2);
  distorted.cameras[1].model =
      CameraModel(test::kWidth, test::kHeight, 20, 20, 7.5, 5.5, Distortion::RadTan, {-0.2, 0.05, 0, 0});
  const Dataset a = Dataset::open(writeAsl(dir, distorted));
  const std::string distorted_error = exportError(a, DatasetLayoutKind::Kitti, dir.file("kitti"));
  EXPECT_NE(distorted_error.find("cam1: distortion radtan"), std::string::npos) << distorted_error;
  EXPECT_FALSE(fs::exists(dir.file("kitti")));

  test::TempDir dir2("export_kitti_turned");
  Rig turned = test::smallRig(2);
  turned.cameras[1].T_b_c.R = Eigen::AngleAxisd(0.01, Vec3::UnitY()).toRotationMatrix();
  const Dataset b = Dataset::open(writeAsl(dir2, turned));
  const std::string turned_error = exportError(b, DatasetLayoutKind::Kitti, dir2.file("kitti"));
  EXPECT_NE(turned_error.find("cam1: turned 0.5730 deg"), std::string::npos) << turned_error;
}

TEST(DatasetExport, RefusesAnOutputFolderThatHoldsSomething) {
  test::TempDir dir("export_exists");
  const Dataset asl = Dataset::open(writeAsl(dir, test::smallRig(1)));
  test::writeFile(dir.file("out/keep.txt"), "mine");
  const std::string error = exportError(asl, DatasetLayoutKind::Euroc, dir.file("out"));
  EXPECT_NE(error.find("already exists"), std::string::npos) << error;
  EXPECT_EQ(test::readFile(dir.file("out/keep.txt")), "mine");
  EXPECT_FALSE(fs::exists(dir.file("out/mav0")));
}

// The pixels of every image of `a` and `b` (same frames and cameras) are equal; b's images are binary PGM files.
void expectSamePixelsInPgm(const Dataset& a, const Dataset& b) {
  ASSERT_EQ(a.size(), b.size());
  std::vector<Image> ia, ib;
  std::vector<bool> pa, pb;
  for (std::size_t i = 0; i < a.size(); ++i) {
    std::string error;
    EXPECT_EQ(a.loadImages(i, ia, pa, &error), b.loadImages(i, ib, pb, &error)) << error;
    ASSERT_EQ(pa, pb) << "frame " << i;
    for (int c = 0; c < a.rig().size(); ++c) {
      if (!pa[c]) continue;
      EXPECT_EQ(fs::path(b.frames()[i].image_paths[c]).extension(), ".pgm");
      EXPECT_EQ(test::readFile(b.frames()[i].image_paths[c]).substr(0, 2), "P5");
      ASSERT_EQ(ia[c].view().width, ib[c].view().width);
      EXPECT_TRUE(std::equal(ia[c].data(), ia[c].data() + ia[c].width() * ia[c].height(), ib[c].data()))
          << "frame " << i;
    }
  }
}

TEST(DatasetExport, PgmImagesRoundTripThroughAslAndEurocWithTheSamePixels) {
  test::TempDir dir("export_pgm");
  const Dataset png = Dataset::open(writeAsl(dir, test::smallRig(2), /*skip_camera=*/1));
  DatasetExportOptions pgm;
  pgm.images = ExportImages::Pgm;
  const DatasetExportReport r = exportDataset(png, DatasetLayoutKind::Asl, dir.file("asl_pgm"), pgm);
  EXPECT_EQ(r.images_written, static_cast<std::size_t>(2 * kFrames - 1));
  const Dataset asl = Dataset::open(dir.file("asl_pgm"));
  expectSamePixelsInPgm(png, asl);
  ASSERT_TRUE(asl.groundTruth());
  EXPECT_EQ(asl.groundTruth()->size(), static_cast<std::size_t>(kFrames));
  // PGM to PGM again, into EuRoC.
  exportDataset(asl, DatasetLayoutKind::Euroc, dir.file("euroc_pgm"), pgm);
  expectSamePixelsInPgm(png, Dataset::open(dir.file("euroc_pgm")));
}

TEST(DatasetExport, KittiRefusesPgmImagesBeforeWritingAnything) {
  test::TempDir dir("export_kitti_pgm");
  const Dataset asl = Dataset::open(writeAsl(dir, test::smallRig(2)));
  DatasetExportOptions pgm;
  pgm.images = ExportImages::Pgm;
  const std::string error = exportError(asl, DatasetLayoutKind::Kitti, dir.file("kitti"), pgm);
  EXPECT_NE(error.find("KITTI layout holds PNG images only"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir.file("kitti")));
}

TEST(DatasetExport, ConvertCommandWritesPgmImagesAndRefusesAnUnknownFormat) {
  test::TempDir dir("export_cli");
  const std::string src = writeAsl(dir, test::smallRig(2));
  std::string out;
  const std::string tool = test::binPath("mcslam-dataset") + " convert " + src + " --layout euroc --out ";
  ASSERT_EQ(test::runCommand(tool + dir.file("euroc") + " --images pgm", &out), 0) << out;
  expectSamePixelsInPgm(Dataset::open(src), Dataset::open(dir.file("euroc")));
  // The default keeps the files as they are (hard links here).
  ASSERT_EQ(test::runCommand(tool + dir.file("euroc_original"), &out), 0) << out;
  const Dataset original = Dataset::open(dir.file("euroc_original"));
  EXPECT_TRUE(fs::equivalent(original.frames()[0].image_paths[1], Dataset::open(src).frames()[0].image_paths[1]));
  EXPECT_EQ(test::runCommand(tool + dir.file("tiff") + " --images tiff", &out), 2);
  EXPECT_NE(out.find("unknown image format 'tiff' (supported: original, pgm)"), std::string::npos) << out;
}

TEST(DatasetExport, ImageFormatNames) {
  EXPECT_EQ(parseExportImages("pgm"), ExportImages::Pgm);
  EXPECT_EQ(parseExportImages("original"), ExportImages::Original);
  EXPECT_THROW(parseExportImages("PNG"), InputError);
}

TEST(DatasetExport, LayoutNames) {
  EXPECT_EQ(parseDatasetLayout("kitti"), DatasetLayoutKind::Kitti);
  EXPECT_STREQ(datasetLayoutName(parseDatasetLayout("euroc")), "euroc");
  EXPECT_THROW(parseDatasetLayout("tum"), InputError);
}
