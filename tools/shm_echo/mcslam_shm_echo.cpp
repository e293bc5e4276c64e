// mcslam-shm-echo: prints the poses mcslamd publishes in shared memory, as they come, using only the
// consumer header include/mcslam/pose_shm.hpp. Reads the ring, so no pose is missed unless the reader
// falls more than ring_length poses behind (then it says how many it missed).
#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "mcslam/pose_shm.hpp"
#include "pose_print.hpp"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-shm-echo: print the poses of mcslamd's shared-memory segment"};
  std::string name = "/mcslam_pose";
  long long count = 0;
  double wait_s = 10;
  bool latest = false;
  app.add_option("--name", name, "Segment name (publish.shm.name)")->capture_default_str();
  app.add_option("--count", count, "Exit after this many poses (0 = until the writer stops or Ctrl-C)");
  app.add_option("--wait", wait_s, "Seconds to wait for the segment to appear")->capture_default_str();
  app.add_flag("--latest", latest, "Print only the latest pose once and exit");
  CLI11_PARSE(app, argc, argv);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);

  mcslam::pose::PoseShmReader reader;
  std::string error;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  while (!reader.open(name, &error)) {
    if (g_stop || std::chrono::steady_clock::now() > deadline) {
      std::fprintf(stderr, "mcslam-shm-echo: %s\n", error.c_str());
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  mcslam::pose::PoseRecord r;
  if (latest) {
    if (reader.readLatest(r) != mcslam::pose::ReadStatus::Ok) {
      std::fprintf(stderr, "mcslam-shm-echo: no pose yet\n");
      return 1;
    }
    mcslam::tools::printPose(r, stdout);
    return 0;
  }
  uint64_t next = 1;
  long long printed = 0;
  while (!g_stop && (count == 0 || printed < count)) {
    const uint64_t newest = reader.published();
    if (next > newest) {
      if (!reader.writerRunning()) break;
      std::this_thread::sleep_for(std::chrono::microseconds(500));
      continue;
    }
    const auto status = reader.readSequence(next, r);
    if (status == mcslam::pose::ReadStatus::Ok) {
      mcslam::tools::printPose(r, stdout);
      ++printed;
      ++next;
    } else if (status == mcslam::pose::ReadStatus::Overwritten) {
      const uint64_t oldest = newest - reader.ringCapacity() + 1;
      std::fprintf(stderr, "mcslam-shm-echo: missed poses %llu..%llu (reader too slow)\n",
                   static_cast<unsigned long long>(next), static_cast<unsigned long long>(oldest - 1));
      next = oldest + 1;
    }
  }
  return 0;
}
