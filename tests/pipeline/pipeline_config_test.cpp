#include <gtest/gtest.h>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/pipeline/pipeline_config.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {
Rig isec() { return loadKalibrRig(test::dataPath("calib/isec_5cam_camchain.yaml")); }

std::string errorOf(const std::string& yaml) {
  try {
    parsePipelineConfig(YAML::Load(yaml), "run.yaml", isec());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(PipelineConfig, AbsentSectionGivesDefaults) {
  const PipelineConfig c = parsePipelineConfig(YAML::Node(), "defaults", isec());
  EXPECT_EQ(c.orb.max_features, 1000);
  EXPECT_EQ(c.odometry.window_keyframes, OdometryOptions{}.window_keyframes);
  EXPECT_NEAR(c.odometry.extrinsic_sigma_rotation_deg, 1.0, 1e-12);
  const PipelineConfig partial = parsePipelineConfig(YAML::Load("capacity: {max_landmarks: 9000}"), "x.yaml", isec());
  EXPECT_EQ(partial.odometry.max_landmarks, 9000);
  EXPECT_EQ(partial.orb.max_features, 1000);  // untouched keys keep their defaults
}

TEST(PipelineConfig, EffectiveConfigReadsBackToTheSameValues) {
  const PipelineConfig c = parsePipelineConfig(
      YAML::Load("features: {levels: 6}\ntracking: {radius_px: 22}\nbackend: {apply_after_frames: 5}"), "x.yaml",
      isec());
  const YAML::Node back = YAML::Load(formatPipelineConfig(c));
  const PipelineConfig d = parsePipelineConfig(back["slam"], "effective", isec());
  EXPECT_EQ(d.orb.levels, 6);
  EXPECT_DOUBLE_EQ(d.odometry.track_radius_px, 22);
  EXPECT_EQ(d.odometry.backend_apply_after_frames, 5);
  EXPECT_EQ(formatPipelineConfig(d), formatPipelineConfig(c));
}

TEST(PipelineConfig, BadValuesNameFileAndKey) {
  EXPECT_NE(errorOf("capacity: {max_featurs: 10}").find("run.yaml: slam.capacity.max_featurs: unknown key"),
            std::string::npos);
  EXPECT_NE(errorOf("capacity: {max_features_per_camera: 0}").find("slam.capacity.max_features_per_camera"),
            std::string::npos);
  EXPECT_NE(errorOf("tracking: {ratio: high}").find("slam.tracking.ratio"), std::string::npos);
  EXPECT_NE(errorOf("backend: {refine_extrinsics: maybe}").find("auto, on, off"), std::string::npos);
  EXPECT_NE(errorOf("backend: {apply_after_frames: 0}").find("slam.backend.apply_after_frames"), std::string::npos);
  EXPECT_NE(errorOf("features: [1, 2]").find("slam.features: must be a map"), std::string::npos);
  EXPECT_NE(errorOf("capacity: {max_keyframes: 8, window_keyframes: 8}").find("max_keyframes"), std::string::npos);
  EXPECT_NE(errorOf("multiview: {min_depth: 5, max_depth: 2}").find("max_depth"), std::string::npos);
}

// backend.refine_extrinsics is read into its enum and written back by name; anything else is an error that names
// the file, the key, the value and the choices.
TEST(PipelineConfig, RefineExtrinsicsIsAnEnumPastTheReader) {
  const auto refine = [](const std::string& value) {
    return parsePipelineConfig(YAML::Load("backend: {refine_extrinsics: " + value + "}"), "x.yaml", isec())
        .refine_extrinsics;
  };
  EXPECT_EQ(parsePipelineConfig(YAML::Node(), "defaults", isec()).refine_extrinsics, RefineExtrinsics::Auto);
  EXPECT_EQ(refine("auto"), RefineExtrinsics::Auto);
  EXPECT_EQ(refine("on"), RefineExtrinsics::On);
  EXPECT_EQ(refine("off"), RefineExtrinsics::Off);
  for (const RefineExtrinsics r : {RefineExtrinsics::Auto, RefineExtrinsics::On, RefineExtrinsics::Off}) {
    PipelineConfig c;
    c.refine_extrinsics = r;
    EXPECT_NE(formatPipelineConfig(c).find(std::string("refine_extrinsics: ") + refineExtrinsicsName(r) + "\n"),
              std::string::npos);
    EXPECT_EQ(refine(refineExtrinsicsName(r)), r);
  }
  const std::string e = errorOf("backend: {refine_extrinsics: maybe}");
  EXPECT_NE(e.find("run.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("slam.backend.refine_extrinsics"), std::string::npos) << e;
  EXPECT_NE(e.find("maybe"), std::string::npos) << e;
  EXPECT_NE(e.find("auto, on, off"), std::string::npos) << e;
}

// config/slam.yaml documents the defaults: it must stay equal to them.
TEST(PipelineConfig, ShippedSlamYamlHoldsTheDefaults) {
  const YAML::Node file = YAML::LoadFile(MCSLAM_SOURCE_DIR "/config/slam.yaml");
  const PipelineConfig shipped = parsePipelineConfig(file["slam"], "config/slam.yaml", isec());
  const PipelineConfig defaults = parsePipelineConfig(YAML::Node(), "defaults", isec());
  EXPECT_EQ(formatPipelineConfig(shipped), formatPipelineConfig(defaults));
}

// Capacities are allocated at start: a huge one, alone or as a product of two in range, is an error naming the key
// and the value before anything is allocated; so is a rig beyond 64 cameras.
TEST(PipelineConfig, CapacitiesBeyondAMachineAndTooManyCamerasAreErrors) {
  EXPECT_NE(errorOf("capacity: {max_landmarks: 1000000000000}")
                .find("slam.capacity.max_landmarks: must be an integer in [500, 2000000], got '1000000000000'"),
            std::string::npos);
  const std::string words =
      errorOf("places: {max_keyframes: 1000000, max_points_per_keyframe: 50, max_words_per_keyframe: 1000000}");
  EXPECT_NE(words.find("run.yaml: slam.places.max_words_per_keyframe: 1000000 times max_keyframes 1000000 is "
                       "1000000000000 word slots"),
            std::string::npos)
      << words;
  EXPECT_NE(errorOf("places: {max_keyframes: 1000000}")
                .find("slam.places.max_points_per_keyframe: 600 times max_keyframes 1000000 is 600000000 point slots"),
            std::string::npos);
  Rig many = isec();
  while (many.size() <= 64) many.cameras.push_back(many.cameras[0]);
  try {
    parsePipelineConfig(YAML::Node(), "run.yaml", many);
    FAIL() << "65 cameras accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at most 64 cameras per rig (got 65)"), std::string::npos) << e.what();
  }
}

// The effective configuration (`--check-config`) quotes a vocabulary path so that it reads back, whatever it holds.
TEST(PipelineConfig, EffectiveConfigQuotesTheVocabularyPath) {
  PipelineConfig c;
  c.places.vocabulary = "dir \"x\"\\voc\ttab.bin";
  const YAML::Node back = YAML::Load(formatPipelineConfig(c));
  EXPECT_EQ(parsePipelineConfig(back["slam"], "effective", isec()).places.vocabulary, c.places.vocabulary);
}
