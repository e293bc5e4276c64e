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
  EXPECT_EQ(c.source_type, SourceType::Dataset);
  EXPECT_EQ(c.rig.size(), 2);
  EXPECT_EQ(c.capacities.rig_ring_slots, 2u);
  EXPECT_EQ(c.publish.shm_name, "/mcslam_pose");
  EXPECT_EQ(c.publish.shm_mode, 0644u);
  EXPECT_EQ(c.trigger.mode, TriggerMode::FreeRunning);
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
  expectError(replay("status_interval_s: 1\nstatus_interval_s: 2\n"), {"status_interval_s", "appears twice", "line"});
  // A calibration file that is missing is blamed on its own key, not on the dataset's path.
  expectError(replay("calibration: no_such_rig.yaml\n"), {"calibration: ", "no_such_rig.yaml"});
  expectError(replay("publish:\n  shm:\n    nam: /x\n"), {"publish.shm.nam", "unknown key"});
  expectError(replay().replace(replay().find("    path"), 0, "    sped: 2\n"), {"source.dataset.sped"});
}

TEST_F(ConfigTest, WrongTypesNameTheKeyAndTheValue) {
  expectError(replay("capacities:\n  rig_ring_slots: many\n"), {"capacities.rig_ring_slots", "'many'"});
  expectError(replay("trigger:\n  rate_hz: [1, 2]\n"), {"trigger.rate_hz", "a list"});
  expectError(replay("publish:\n  udp:\n    destinations: 127.0.0.1:9000\n"), {"publish.udp.destinations", "list"});
  expectError(replay("realtime:\n  lock_memory: maybe\n"), {"realtime.lock_memory", "'maybe'"});
  expectError(replay("realtime:\n  cpus: [0, 1024]\n"), {"realtime.cpus", "item 1", "CPU number from 0 to 1023"});
  expectError(replay("realtime:\n  cpus: 2\n"), {"realtime.cpus", "list of CPU numbers"});
  expectError(replay("publish:\n  shm:\n    mode: \"0999\"\n"), {"publish.shm.mode", "0999"});
  expectError(replay("trigger:\n  mode: laser\n"), {"trigger.mode", "'laser'"});
}

TEST_F(ConfigTest, ZeroCapacitiesAreRefused) {
  for (const char* key :
       {"max_cameras", "camera_ring_slots", "pending_rig_frames", "rig_ring_slots", "pose_ring_slots"})
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
  expectError("calibration: " + calib_ +
                  "\nsource:\n  type: aravis\n  aravis:\n    cameras: [{id: a}, {id: b}, {id: c}]\n"
                  "trigger:\n  mode: gpio\n",
              {"trigger.gpio_chip", "required"});
  expectError("source:\n  type: dataset\n", {"source.dataset.path", "missing"});
  expectError("source:\n  type: aravis\n  aravis:\n    cameras: [{id: a}]\n", {"calibration", "missing"});
  expectError(replay().replace(replay().find(dataset_), dataset_.size(), dir_.file("nowhere")),
              {"source.dataset.path"});
  expectError("source: [dataset]\n", {"'source' must be a map"});
  expectError("source:\n  type: dataset\n  dataset: {path: x}\n  aravis: {}\n", {"source.aravis"});
}

TEST_F(ConfigTest, MalformedYamlIsReportedWithTheFile) { expectError("source: {type: dataset\n", {"not valid YAML"}); }

// A configuration path that names a device which never ends (/dev/zero) is read only up to what a configuration
// could hold, then refused: no reading until memory runs out.
TEST_F(ConfigTest, AnEndlessFileIsRefusedAfterABoundedRead) {
  try {
    loadDaemonConfig("/dev/zero");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/zero: larger than 16 MB"), std::string::npos) << e.what();
  }
}

TEST_F(ConfigTest, SimSourceGetsThePresetsCamerasAndDefaults) {
  const DaemonConfig c = parseDaemonConfig(
      "source:\n  type: sim\n  sim:\n    rig: isec\n    cameras: [0, 1, 2, 3, 4]\n    world: corridor\n",
      dir_.file("sim.yaml"));
  EXPECT_EQ(c.source_type, SourceType::Sim);
  EXPECT_EQ(c.rig.size(), 5);
  EXPECT_EQ(c.rig.model(0).width(), 720);
  EXPECT_EQ(c.sim.world, "corridor");
  EXPECT_EQ(c.sim.pace, SimPace::Fastest);
  EXPECT_EQ(c.sim.at_end, AtEnd::Loop);
  EXPECT_TRUE(
      exitsAtEnd(parseDaemonConfig("source:\n  type: sim\n  sim: {rig: stereo, at_end: exit}\n", dir_.file("s.yaml"))));
  const std::string effective = effectiveDaemonConfig(c);
  EXPECT_NE(effective.find("world: corridor"), std::string::npos) << effective;
  EXPECT_NE(effective.find("cameras: [0, 1, 2, 3, 4]"), std::string::npos) << effective;
  // A rig file is taken relative to the configuration, like every path.
  const DaemonConfig f = parseDaemonConfig("source:\n  type: sim\n  sim: {rig: camchain.yaml}\n", dir_.file("f.yaml"));
  EXPECT_EQ(f.sim.rig, calib_);
  EXPECT_EQ(f.rig.size(), 3);
}

TEST_F(ConfigTest, SimSourceErrorsNameTheKeyAndTheValue) {
  const std::string sim = "source:\n  type: sim\n  sim:\n";
  expectError(sim + "    wrold: indoor\n", {"source.sim.wrold", "unknown key"});
  expectError(sim + "    world: moon\n", {"source.sim.world", "'moon'", "indoor"});
  expectError(sim + "    trajectory: flying\n", {"source.sim.trajectory", "'flying'"});
  expectError(sim + "    rig: octopus\n", {"source.sim.rig", "octopus"});
  expectError(sim + "    rig: stereo\n    cameras: [0, 7]\n", {"source.sim.cameras", "7"});
  expectError(sim + "    rate_hz: 0\n", {"source.sim.rate_hz"});
  expectError(sim + "    pace: warp\n", {"source.sim.pace", "'warp'"});
  expectError(sim + "    frames: -3\n", {"source.sim.frames"});
  expectError("calibration: " + calib_ + "\n" + sim + "    rig: stereo\n", {"calibration", "source.sim.rig"});
  expectError(sim + "    rig: stereo\ntrigger:\n  mode: gpio\n  gpio_chip: gpiochip0\n  gpio_line: 1\n",
              {"trigger", "gpio"});
  expectError("source:\n  type: sim\n  dataset: {path: x}\n", {"source.dataset", "source.type is sim"});
}

// The enumerated settings are enums past the reader: every name users write maps to its value and is written back
// by --check-config under the same name; any other value is refused naming the key, the value and the choices.
TEST_F(ConfigTest, EnumeratedSettingsAreReadIntoEnumsAndWrittenBackByName) {
  for (const auto& [name, rate] :
       {std::pair{"recorded", ReplayRate::Recorded}, std::pair{"fastest", ReplayRate::Fastest}}) {
    for (const auto& [end_name, end] :
         {std::pair{"exit", AtEnd::Exit}, std::pair{"loop", AtEnd::Loop}, std::pair{"idle", AtEnd::Idle}}) {
      const std::string yaml = replay(std::string("    rate: ") + name + "\n    at_end: " + end_name + "\n");
      const DaemonConfig c = parseDaemonConfig(yaml, dir_.file("ok.yaml"));
      EXPECT_EQ(c.dataset.rate, rate) << yaml;
      EXPECT_EQ(c.dataset.at_end, end) << yaml;
      EXPECT_EQ(exitsAtEnd(c), end == AtEnd::Exit);
      const std::string effective = effectiveDaemonConfig(c);
      EXPECT_NE(effective.find(std::string("rate: ") + name + "\n"), std::string::npos) << effective;
      EXPECT_NE(effective.find(std::string("at_end: ") + end_name + "\n"), std::string::npos) << effective;
    }
  }
  for (const auto& [name, mode] :
       {std::pair{"free_running", TriggerMode::FreeRunning}, std::pair{"software", TriggerMode::Software}}) {
    const DaemonConfig c =
        parseDaemonConfig(replay(std::string("trigger:\n  mode: ") + name + "\n"), dir_.file("ok.yaml"));
    EXPECT_EQ(c.trigger.mode, mode);
    EXPECT_NE(effectiveDaemonConfig(c).find(std::string("mode: ") + name + "\n"), std::string::npos);
  }
  const DaemonConfig gpio =
      parseDaemonConfig("calibration: " + calib_ +
                            "\nsource:\n  type: aravis\n  aravis:\n    cameras: [{id: a}, {id: b}, {id: c}]\n"
                            "trigger:\n  mode: gpio\n  gpio_chip: gpiochip0\n  gpio_line: 3\n",
                        dir_.file("ok.yaml"));
  EXPECT_EQ(gpio.source_type, SourceType::Aravis);
  EXPECT_EQ(gpio.trigger.mode, TriggerMode::Gpio);
  EXPECT_NE(effectiveDaemonConfig(gpio).find("type: aravis\n"), std::string::npos);
  EXPECT_NE(effectiveDaemonConfig(gpio).find("mode: gpio\n"), std::string::npos);
  for (const auto& [name, match] : {std::pair{"trigger_count", RigAssembler::MatchBy::TriggerCount},
                                    std::pair{"timestamp", RigAssembler::MatchBy::Timestamp}}) {
    const DaemonConfig c =
        parseDaemonConfig(replay(std::string("assembly:\n  match_by: ") + name + "\n"), dir_.file("ok.yaml"));
    EXPECT_EQ(c.assembly.match_by, match);
    EXPECT_NE(effectiveDaemonConfig(c).find(std::string("match_by: ") + name + "\n"), std::string::npos);
  }
  const DaemonConfig sim = parseDaemonConfig(
      "source:\n  type: sim\n  sim: {rig: stereo, pace: realtime, at_end: idle}\n", dir_.file("ok.yaml"));
  EXPECT_EQ(sim.sim.pace, SimPace::Realtime);
  EXPECT_EQ(sim.sim.at_end, AtEnd::Idle);
  EXPECT_FALSE(exitsAtEnd(sim));
  EXPECT_NE(effectiveDaemonConfig(sim).find("pace: realtime\n"), std::string::npos);
  EXPECT_NE(effectiveDaemonConfig(sim).find("type: sim\n"), std::string::npos);
}

TEST_F(ConfigTest, AnUnknownEnumeratedValueIsRefusedWithTheChoices) {
  expectError(replay("    rate: slow\n"), {"source.dataset.rate", "'slow' is not one of: recorded, fastest"});
  expectError(replay("    at_end: stop\n"), {"source.dataset.at_end", "'stop' is not one of: exit, loop, idle"});
  expectError(replay("trigger:\n  mode: laser\n"),
              {"trigger.mode", "'laser' is not one of: free_running, software, gpio"});
  expectError(replay("assembly:\n  match_by: luck\n"),
              {"assembly.match_by", "'luck' is not one of: trigger_count, timestamp"});
  expectError("source:\n  type: sim\n  sim:\n    pace: warp\n",
              {"source.sim.pace", "'warp' is not one of: fastest, realtime"});
  expectError("source:\n  type: camera\n", {"source.type", "'camera' is not one of: dataset, aravis, sim"});
  expectError("source: {}\n", {"source.type", "missing (required): dataset, aravis or sim"});
}
