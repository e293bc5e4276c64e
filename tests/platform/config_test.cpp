// mcslamd's configuration: strict parsing with one clear message naming the file, the key and the value;
// defaults and the effective configuration.
#include <gtest/gtest.h>

#include "daemon/daemon_config.hpp"
#include "daemon_fixture.hpp"
#include "mcslam/core/error.hpp"
#include "test_support.hpp"

using namespace mcslam;
using namespace mcslam::platform;

namespace {
class ConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dataset_ = test::writeSmallDataset(dir_.file("data"), 2, 3);
    calib_ = dir_.file("camchain.yaml");
    writeKalibrRig(test::smallRig(3, 64, 48), calib_);
  }
  std::string replay(const std::string& extra = "") const {
    return "source:\n  type: dataset\n  dataset:\n    path: " + dataset_ + "\n" + extra;
  }
  // Expects an InputError whose message contains every fragment.
  void expectError(const std::string& yaml, std::vector<std::string> fragments) {
    const std::string file = dir_.file("bad.yaml");
    try {
      parseDaemonConfig(yaml, file);
      FAIL() << "accepted:\n" << yaml;
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(file), std::string::npos) << m;
      for (const auto& f : fragments) EXPECT_NE(m.find(f), std::string::npos) << "'" << f << "' not in: " << m;
    }
  }
  test::TempDir dir_{"config"};
  std::string dataset_, calib_;
};
}  // namespace

TEST_F(ConfigTest, ReplayConfigGetsDefaultsAndTheDatasetsRig) {
  const DaemonConfig c = parseDaemonConfig(replay(), dir_.file("ok.yaml"));
  EXPECT_EQ(c.source_type, "dataset");
  EXPECT_EQ(c.rig.size(), 2);
  EXPECT_EQ(c.capacities.rig_ring_slots, 2u);
  EXPECT_EQ(c.publish.shm_name, "/mcslam_pose");
  EXPECT_EQ(c.publish.shm_mode, 0644u);
  EXPECT_EQ(c.trigger.mode, "free_running");
  const std::string effective = effectiveDaemonConfig(c);
  EXPECT_NE(effective.find("rig_ring_slots: 2"), std::string::npos) << effective;
  EXPECT_NE(effective.find("slam:"), std::string::npos) << effective;
  EXPECT_NE(effective.find("\"0644\""), std::string::npos) << effective;
}

TEST_F(ConfigTest, RelativePathsAreTakenFromTheConfigFilesFolder) {
  const DaemonConfig c =
      parseDaemonConfig("source:\n  type: dataset\n  dataset:\n    path: data\n", dir_.file("rel.yaml"));
  EXPECT_EQ(c.dataset.path, dir_.file("data"));
}

TEST_F(ConfigTest, UnknownKeysAreNamedWithTheirPath) {
  expectError(replay("bogus: 1\n"), {"bogus", "unknown key"});
  expectError(replay("publish:\n  shm:\n    nam: /x\n"), {"publish.shm.nam", "unknown key"});
  expectError(replay().replace(replay().find("    path"), 0, "    sped: 2\n"), {"source.dataset.sped"});
}

TEST_F(ConfigTest, WrongTypesNameTheKeyAndTheValue) {
  expectError(replay("capacities:\n  rig_ring_slots: many\n"), {"capacities.rig_ring_slots", "'many'"});
  expectError(replay("trigger:\n  rate_hz: [1, 2]\n"), {"trigger.rate_hz", "a list"});
  expectError(replay("publish:\n  udp:\n    destinations: 127.0.0.1:9000\n"), {"publish.udp.destinations", "list"});
  expectError(replay("realtime:\n  lock_memory: maybe\n"), {"realtime.lock_memory", "'maybe'"});
  expectError(replay("publish:\n  shm:\n    mode: \"0999\"\n"), {"publish.shm.mode", "0999"});
  expectError(replay("trigger:\n  mode: laser\n"), {"trigger.mode", "'laser'"});
}

TEST_F(ConfigTest, ZeroCapacitiesAreRefused) {
  for (const char* key : {"max_cameras", "camera_ring_slots", "pending_rig_frames", "rig_ring_slots", "pose_ring_slots"})
    expectError(replay("capacities:\n  " + std::string(key) + ": 0\n"),
                {"capacities." + std::string(key), "at least 1"});
  expectError(replay("publish:\n  shm:\n    ring_length: 0\n"), {"publish.shm.ring_length", "at least 1"});
}

TEST_F(ConfigTest, CameraCountMustMatchTheCalibration) {
  expectError("calibration: " + calib_ +
                  "\nsource:\n  type: aravis\n  aravis:\n    cameras:\n      - {id: a}\n      - {id: b}\n",
              {"source.aravis", "2 cameras", "has 3"});
  expectError(replay("capacities:\n  max_cameras: 1\n"), {"capacities.max_cameras", "2 cameras"});
}

TEST_F(ConfigTest, InconsistentCombinationsAreRefused) {
  expectError(replay("trigger:\n  mode: gpio\n  gpio_chip: gpiochip0\n  gpio_line: 1\n"), {"trigger", "gpio"});
  expectError("calibration: " + calib_ + "\nsource:\n  type: aravis\n  aravis:\n    cameras: [{id: a}, {id: b}, {id: c}]\n"
              "trigger:\n  mode: gpio\n",
              {"trigger.gpio_chip", "required"});
  expectError("source:\n  type: dataset\n", {"source.dataset.path", "missing"});
  expectError("source:\n  type: aravis\n  aravis:\n    cameras: [{id: a}]\n", {"calibration", "missing"});
  expectError(replay().replace(replay().find(dataset_), dataset_.size(), dir_.file("nowhere")),
              {"source.dataset.path"});
  expectError("source: [dataset]\n", {"'source' must be a map"});
  expectError("source:\n  type: dataset\n  dataset: {path: x}\n  aravis: {}\n", {"source.aravis"});
}

TEST_F(ConfigTest, MalformedYamlIsReportedWithTheFile) {
  expectError("source: {type: dataset\n", {"not valid YAML"});
}
