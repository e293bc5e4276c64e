// tools/pose_client.py, written from docs/pose-protocol.md alone, decodes what the daemon's UDP sender
// emits: its lines equal the C++ echo tools' lines for the same records.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "../../tools/shm_echo/pose_print.hpp"
#include "test_support.hpp"
#include "udp/udp_pose_sender.hpp"

using namespace mcslam;

namespace {
std::string readLine(std::FILE* f) {
  char buf[1024];
  return std::fgets(buf, sizeof(buf), f) ? std::string(buf) : std::string();
}

std::string printed(const pose::PoseRecord& r) {
  char* text = nullptr;
  std::size_t size = 0;
  std::FILE* mem = open_memstream(&text, &size);
  tools::printPose(r, mem);
  std::fclose(mem);
  std::string s(text, size);
  std::free(text);
  return s;
}
}  // namespace

TEST(PoseClientPy, DecodesTheDaemonsDatagramsLikeTheCppTools) {
  if (test::runCommand("python3 --version") != 0) GTEST_SKIP() << "python3 is not installed";
  const std::string script = std::string(MCSLAM_TEST_DATA_DIR) + "/../../tools/pose_client.py";
  std::FILE* client =
      ::popen(("python3 " + script + " --bind 127.0.0.1 --port 0 --count 3 --timeout 20 2>&1").c_str(), "r");
  ASSERT_NE(client, nullptr);
  const std::string hello = readLine(client);  // "listening on 127.0.0.1:PORT"
  const auto colon = hello.rfind(':');
  ASSERT_NE(colon, std::string::npos) << hello;
  const std::string dest = "127.0.0.1:" + std::to_string(std::stoi(hello.substr(colon + 1)));
  platform::UdpPoseSender sender({platform::resolveUdpDestination(dest, "publish.udp.destinations")});
  pose::PoseRecord records[3];
  for (int i = 0; i < 3; ++i) {
    pose::PoseRecord& r = records[i];
    r.sequence = 1 + i;
    r.frame_sequence = 10 + 2 * i;
    r.capture_time_ns = 1403636579763555584ll + i * 50000000ll;
    r.publish_time_ns = 1700000000000000000ll;
    r.position[0] = 0.1 * i;
    r.position[1] = -1.0 / 3.0;
    r.position[2] = 1e-9 * i;
    r.orientation[0] = 0.5;
    r.orientation[1] = -0.5;
    r.orientation[2] = 0.5;
    r.orientation[3] = 0.5;
    r.tracking = static_cast<pose::Tracking>(i);
    r.flags = static_cast<uint8_t>(i == 1   ? pose::kFlagValid
                                   : i == 2 ? pose::kFlagValid | pose::kFlagUnscaled | pose::kFlagUnanchored
                                            : 0);
    r.world_revision = static_cast<uint16_t>(65535 * i / 2);
    r.quality = 0.25f * i;
  }
  // The client bound its socket before saying "listening", so nothing sent now is lost.
  for (int i = 0; i < 3; ++i) {
    sender.send(records[i]);
    const std::string line = readLine(client);
    EXPECT_EQ(line, printed(records[i]));
  }
  EXPECT_EQ(::pclose(client), 0);
}
