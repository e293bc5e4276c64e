#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "dataset_test_util.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/dataset_export.hpp"

using namespace mcslam;
namespace fs = std::filesystem;

namespace {

// The rectified entries of drive 2011_09_26_drive_0001's calib_cam_to_cam.txt, with the size made small, among
// the entries the reader must pass over (calib_time, the unrectified K_00, R_rect_00).
std::string calibText(const std::string& s_rect_01 = "4.000000e+01 1.200000e+01") {
  return "calib_time: 09-Jan-2012 13:57:47\n"
         "corner_dist: 9.950000e-02\n"
         "K_00: 9.842439e+02 0.000000e+00 6.900000e+02 0.000000e+00 9.808141e+02 2.331966e+02 0 0 1\n"
         "S_rect_00: 4.000000e+01 1.200000e+01\n"
         "R_rect_00: 9.999239e-01 9.837760e-03 -7.445048e-03 -9.869795e-03 9.999421e-01 -4.278459e-03 "
         "7.402527e-03 4.351614e-03 9.999631e-01\n"
         "P_rect_00: 7.215377e+02 0 6.095593e+02 0 0 7.215377e+02 1.728540e+02 0 0 0 1 0\n"
         "S_rect_01: " +
         s_rect_01 +
         "\n"
         "P_rect_01: 7.215377e+02 0 6.095593e+02 -3.875744e+02 0 7.215377e+02 1.728540e+02 0 0 0 1 0\n"
         "S_rect_02: 4.000000e+01 1.200000e+01\n"
         "P_rect_02: 7.215377e+02 0 6.095593e+02 4.485728e+01 0 7.215377e+02 1.728540e+02 2.163791e-01 0 0 1 "
         "2.745884e-03\n";
}

constexpr Timestamp kT0 = 1317042145967790592;  // 2011-09-26 13:02:25.967790592

// Three stamps a camera, 0.1 s apart, `offset_ms` after the first; as timestamps.txt writes them.
std::string stamps(int offset_ms) {
  std::string out;
  for (int i = 0; i < 3; ++i) {
    char line[64];
    std::snprintf(line, sizeof(line), "2011-09-26 13:02:%02d.%09d\n", 25 + (967 + 100 * i + offset_ms) / 1000,
                  ((967 + 100 * i + offset_ms) % 1000) * 1000000 + 790592);
    out += line;
  }
  return out;
}

// 2011_09_26/{calib_cam_to_cam.txt, drive_0001_sync/image_0{0,1,2}/{timestamps.txt,data/}}: grey cameras 00 and
// 01, colour camera 02 stamping 6 ms earlier (as the real drive's colour cameras do); image_01's image 1 missing.
std::string writeDrive(const test::TempDir& dir) {
  const fs::path date = dir.path() / "2011_09_26", drive = date / "2011_09_26_drive_0001_sync";
  test::writeFile((date / "calib_cam_to_cam.txt").string(), calibText());
  for (int k = 0; k < 3; ++k) {
    const fs::path cam = drive / ("image_0" + std::to_string(k));
    test::writeFile((cam / "timestamps.txt").string(), stamps(k == 2 ? -6 : 0));
    for (int i = 0; i < 3; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%010d.png", i);
      if (k == 1 && i == 1) continue;
      if (k == 2) {
        fs::create_directories(cam / "data");
        cv::imwrite((cam / "data" / name).string(), cv::Mat(12, 40, CV_8UC3, cv::Scalar(10, 20, 30)));  // B, G, R
      } else {
        test::writePng((cam / "data" / name).string(), static_cast<uint8_t>(10 * k + i), 40, 12);
      }
    }
  }
  return drive.string();
}

std::string openError(const std::string& dir) {
  try {
    Dataset::open(dir);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST(KittiRawDataset, RigFromTheRectifiedEntriesWithTheBodyAtRectifiedCamera0) {
  test::TempDir dir("kittiraw");
  const Dataset ds = Dataset::open(writeDrive(dir));
  EXPECT_EQ(ds.format(), "kitti_raw");
  ASSERT_EQ(ds.rig().size(), 3);
  const CameraModel& m = ds.rig().model(2);
  EXPECT_DOUBLE_EQ(m.fx(), 721.5377);
  EXPECT_DOUBLE_EQ(m.cy(), 172.854);
  EXPECT_EQ(m.distortion(), Distortion::None);
  EXPECT_EQ(m.width(), 40);  // S_rect_02
  EXPECT_EQ(m.height(), 12);
  EXPECT_TRUE(ds.rig().T_b_c(0).t.isZero(0));
  EXPECT_LT((ds.rig().T_b_c(1).t - Vec3(387.5744 / 721.5377, 0, 0)).norm(), 1e-12);  // 0.537 m to the right
  // t = K^-1 P(:,3) is camera 0 -> camera 2; camera 2 sits at -t.
  const double tz = 2.745884e-03, ty = (2.163791e-01 - 172.854 * tz) / 721.5377,
               tx = (44.85728 - 609.5593 * tz) / 721.5377;
  EXPECT_LT((ds.rig().T_b_c(2).t - Vec3(-tx, -ty, -tz)).norm(), 1e-12);
  EXPECT_TRUE(ds.rig().T_b_c(2).R.isIdentity(0));
  EXPECT_FALSE(ds.groundTruth().has_value());
}

TEST(KittiRawDataset, CamerasStampedMillisecondsApartShareTheirFramesAndColourIsReadAsGrey) {
  test::TempDir dir("kittiraw");
  const Dataset ds = Dataset::open(writeDrive(dir));
  ASSERT_EQ(ds.size(), 3u);                    // not 6: the 6 ms between the pairs is within one frame
  EXPECT_EQ(ds.frames()[0].t, kT0 - 6000000);  // the earliest stamp of the frame: the colour camera's
  EXPECT_EQ(ds.frames()[2].camera_stamps[0], kT0 + 200000000);
  EXPECT_TRUE(ds.frames()[1].image_paths[1].empty());
  ASSERT_FALSE(ds.warnings().empty());
  EXPECT_NE(ds.warnings()[0].find("image_01/timestamps.txt: line 2: image "), std::string::npos) << ds.warnings()[0];
  std::vector<Image> images;
  std::vector<bool> present;
  std::string error;
  ASSERT_EQ(ds.loadImages(2, images, present, &error), 3) << error;
  EXPECT_EQ(images[1].data()[0], 12);
  // Grey as a weighted mean of B 10, G 20, R 30: libpng's weights (BT.709) give 21, BT.601's 22.
  EXPECT_NEAR(images[2].data()[0], 21.5, 1.0);
}

TEST(KittiRawDataset, ConvertedIntoTheEurocLayoutItKeepsItsRigFrames) {
  test::TempDir dir("kittiraw");
  const Dataset raw = Dataset::open(writeDrive(dir));
  exportDataset(raw, DatasetLayoutKind::Euroc, dir.file("euroc"), {ExportImages::Pgm});
  const Dataset euroc = Dataset::open(dir.file("euroc"));
  ASSERT_EQ(euroc.size(), raw.size());  // the 6 ms apart stamps, as written, would make 6 frames of one camera
  EXPECT_EQ(euroc.frames()[2].t, raw.frames()[2].t);
  EXPECT_FALSE(euroc.frames()[2].image_paths[2].empty());
}

TEST(KittiRawDataset, CalibrationInTheDriveFolderItself) {
  test::TempDir dir("kittiraw");
  const std::string drive = writeDrive(dir);
  fs::rename(dir.path() / "2011_09_26" / "calib_cam_to_cam.txt", fs::path(drive) / "calib_cam_to_cam.txt");
  EXPECT_EQ(Dataset::open(drive + "/").rig().size(), 3);
  fs::remove(fs::path(drive) / "calib_cam_to_cam.txt");
  EXPECT_NE(openError(drive).find("KITTI raw images (image_00/) but no calib_cam_to_cam.txt"), std::string::npos);
}

TEST(KittiRawDataset, MalformedCalibrationNamesFileLineEntryAndValue) {
  test::TempDir dir("kittiraw");
  const std::string drive = writeDrive(dir);
  const std::string calib = (dir.path() / "2011_09_26" / "calib_cam_to_cam.txt").string();
  const auto expectError = [&](const std::string& text, const std::string& expected) {
    test::writeFile(calib, text);
    const std::string error = openError(drive);
    EXPECT_NE(error.find(expected), std::string::npos) << error;
  };
  const auto replaced = [](std::string text, const std::string& from, const std::string& to) {
    return text.replace(text.find(from), from.size(), to);
  };
  const std::string base = calibText();
  expectError(calibText("4.000000e+01 1.2e+01x"), calib + ": line 7: S_rect_01 entry is not a number: '1.2e+01x'");
  expectError(calibText("40.5 12"),
              "line 7: S_rect_01 must be two whole numbers of pixels (width height), got 40.5 12");
  expectError(calibText("40"), "line 7: S_rect_01 must have 2 numbers (the rectified image's width and height), got 1");
  expectError(replaced(base, "2.745884e-03\n", "\n"),
              "line 10: P_rect_02 must have 12 numbers (a 3x4 projection matrix, row by row), got 11");
  expectError(replaced(base, "1.728540e+02 0 0 0 1 0\nS_rect_01", "1.728540e+02 0 0 0 2 0\nS_rect_01"),
              "line 6: P_rect_00 is not a rectified projection");
  expectError(replaced(base, "S_rect_02: 4.000000e+01 1.200000e+01\n", ""), calib + ": no S_rect_02 for the images in");
  expectError(base + "P_rect_01: 1 0 0 0 0 1 0 0 0 0 1 0\n", "line 11: P_rect_01 is given twice (first on line 8)");
}

TEST(KittiRawDataset, MalformedTimestampsNameFileLineAndValue) {
  test::TempDir dir("kittiraw");
  const std::string drive = writeDrive(dir);
  const std::string times = drive + "/image_02/timestamps.txt";
  const auto expectError = [&](const std::string& text, const std::string& expected) {
    test::writeFile(times, text);
    const std::string error = openError(drive);
    EXPECT_NE(error.find(times + ": " + expected), std::string::npos) << error;
  };
  expectError("2011-09-26 13:02:25.961790592\n2011-09-26 13:02:2x.061790592\n",
              "line 2 (image 1): expected 'YYYY-MM-DD hh:mm:ss.fraction', got '2011-09-26 13:02:2x.061790592'");
  expectError("2011-02-30 13:02:25.961790592\n", "line 1 (image 0)");  // no 30 February
  expectError("2011-09-26 13:02:25.961790592\n2011-09-26 13:02:25.961790592\n", "line 2: times must increase");
}
