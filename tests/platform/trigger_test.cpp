// Trigger logic: the schedule skips (and counts) pulses it woke too late for, the pulse output drives a
// line active then idle, the thread fires consecutive indices and logs their times, and the libgpiod
// adapter reports a missing chip with the config key.
#include <gtest/gtest.h>

#include <mutex>
#include <thread>
#include <vector>

#include "gpio/gpiod_line.hpp"
#include "gpio/trigger_line.hpp"
#include "mcslam/core/error.hpp"
#include "trigger/trigger_schedule.hpp"
#include "trigger/trigger_thread.hpp"

using namespace mcslam;
using namespace mcslam::platform;

namespace {
class FakeLine : public TriggerLine {
 public:
  bool set(bool active) override {
    levels.push_back(active);
    if (fail_next) {
      fail_next = false;
      return false;
    }
    return true;
  }
  std::vector<bool> levels;
  bool fail_next = false;
};

class RecordingOutput : public TriggerOutput {
 public:
  bool fire(uint64_t index) override {
    std::lock_guard<std::mutex> lock(m);
    indices.push_back(index);
    return true;
  }
  std::mutex m;
  std::vector<uint64_t> indices;
};
}  // namespace

TEST(TriggerSchedule, FiresOnTimeAndSkipsWhatItMissed) {
  TriggerSchedule s(1000, 100);  // pulses due at 1000, 1100, 1200, ...
  EXPECT_FALSE(s.onWake(999));
  EXPECT_TRUE(s.onWake(1000));
  EXPECT_EQ(s.nextDeadline(), 1100);
  EXPECT_TRUE(s.onWake(1150));  // late but before the next one is due: fires, nothing missed
  EXPECT_EQ(s.missed(), 0u);
  EXPECT_EQ(s.nextDeadline(), 1200);
  EXPECT_TRUE(s.onWake(1530));  // 1200, 1300, 1400 fully passed: one pulse now, three missed
  EXPECT_EQ(s.missed(), 3u);
  EXPECT_EQ(s.nextDeadline(), 1600);
}

TEST(PulseTrigger, DrivesTheLineActiveThenIdleAndNeverLeavesItActive) {
  FakeLine line;
  PulseTrigger pulse(line, 1000);
  EXPECT_TRUE(pulse.fire(0));
  EXPECT_TRUE(pulse.fire(1));
  EXPECT_EQ(line.levels, (std::vector<bool>{true, false, true, false}));
  line.fail_next = true;
  EXPECT_FALSE(pulse.fire(2));  // raising failed: reported, and the line is still set idle
  EXPECT_EQ(line.levels.back(), false);
}

TEST(TriggerThread, FiresConsecutiveIndicesAndLogsTheirTimes) {
  RecordingOutput out;
  TriggerLog log;
  TriggerThread thread(out, log, 200.0, 0);
  thread.start();
  for (int i = 0; i < 400; ++i) {  // liveness only: wait (up to 4 s) for 5 pulses
    {
      std::lock_guard<std::mutex> lock(out.m);
      if (out.indices.size() >= 5) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  thread.stop();
  std::lock_guard<std::mutex> lock(out.m);
  ASSERT_GE(out.indices.size(), 5u);
  for (std::size_t i = 0; i < out.indices.size(); ++i) EXPECT_EQ(out.indices[i], i);
  EXPECT_EQ(thread.fired(), out.indices.size());
  EXPECT_GT(log.lookup(0), 0);
  EXPECT_GE(log.lookup(1), log.lookup(0));
  EXPECT_EQ(log.lookup(out.indices.size() + 10), 0);  // never fired
}

TEST(GpiodLine, MissingChipIsAClearStartupError) {
  try {
    GpiodLine line("gpiochip-mcslam-missing", 3, false);
    FAIL() << "opening a missing chip succeeded";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("trigger.gpio_chip"), std::string::npos) << m;
    EXPECT_NE(m.find("gpiochip-mcslam-missing"), std::string::npos) << m;
  }
}

TEST(GpiodLine, NotAGpioDeviceIsRefusedWithTheKey) {
  try {
    GpiodLine line("/dev/null", 0, false);
    FAIL() << "/dev/null was accepted as a GPIO chip";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("trigger.gpio_chip"), std::string::npos) << e.what();
  }
}
