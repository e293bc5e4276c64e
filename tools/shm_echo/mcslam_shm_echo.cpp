// mcslam-shm-echo: prints the poses mcslamd publishes in shared memory, as they come, using only the
// consumer header include/mcslam/pose_shm.hpp. Reads the ring, so no pose is missed unless the reader
// falls more than ring_length poses behind (then it says how many it missed). Follows a restarted daemon:
// when the writer is gone or its segment replaced, it reattaches to the new segment (a line on stderr) or
// exits 1 when none comes within --wait seconds.
#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "mcslam/pose_shm.hpp"
#include "pose_print.hpp"

namespace {
using mcslam::pose::PoseShmReader;
using mcslam::pose::ReadStatus;
using mcslam::pose::SegmentStatus;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }

// Reads in a row that gave no pose although `published` said there was one: a consistent segment never
// comes near this, an inconsistent header (or a writer stuck inside a slot) reaches it quickly.
constexpr int kMaxFailedReads = 1000;
// Idle polls (0.5 ms apart) between two check() calls.
constexpr int kPollsPerCheck = 200;

// Opens `name` and waits up to wait_s for a segment whose writer runs or stopped cleanly (then what it
// holds is printed); any segment when !need_writer.
bool attach(PoseShmReader& reader, const std::string& name, double wait_s, bool need_writer, std::string& error) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(wait_s);
  for (;;) {
    if (reader.open(name, &error)) {
      const SegmentStatus s = reader.check();
      if (s == SegmentStatus::Live || s == SegmentStatus::Stopped || !need_writer) return true;
      error = name + ": " + mcslam::pose::segmentStatusName(s) + " (writer pid " + std::to_string(reader.writerPid()) +
              "), and no new segment appeared";
      reader.close();
    }
    if (g_stop || Clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// Where a reader starts: the oldest pose still in the ring.
uint64_t firstSequence(const PoseShmReader& reader) {
  const uint64_t newest = reader.published();
  return newest < reader.ringCapacity() ? 1 : newest - reader.ringCapacity() + 1;
}

class Echo {
 public:
  Echo(std::string name, double wait_s) : name_(std::move(name)), wait_s_(wait_s) {}

  // The exit status.
  int run(long long count, bool latest) {
    PoseShmReader::guardAgainstTruncation();  // a truncated segment must not end us with SIGBUS
    std::string error;
    if (!attach(reader_, name_, wait_s_, !latest, error)) return failure(error);
    if (latest) return printLatest();
    next_ = firstSequence(reader_);
    while (!g_stop && (count == 0 || printed_ < count)) {
      const int status = step();
      if (status >= 0) return status;
    }
    return 0;
  }

 private:
  // One read or one idle poll; an exit status when the echo ends, else -1.
  int step() {
    const uint64_t newest = reader_.published();
    if (next_ > newest) {
      if (++polls_ % kPollsPerCheck == 0 || !reader_.writerRunning()) return follow();
      std::this_thread::sleep_for(std::chrono::microseconds(500));
      return -1;
    }
    mcslam::pose::PoseRecord r;
    const ReadStatus status = reader_.readSequence(next_, r);
    if (status == ReadStatus::Ok) {
      reportMissed();
      mcslam::tools::printPose(r, stdout);
      ++printed_;
      ++next_;
      failed_ = 0;
      return -1;
    }
    if (status == ReadStatus::Overwritten) {
      if (missed_from_ == 0) missed_from_ = next_;
      next_ = std::max(next_ + 1, firstSequence(reader_) + 1);  // +1: the oldest is next to be overwritten
    }
    if (++failed_ < kMaxFailedReads) return -1;
    if (reader_.check() != SegmentStatus::Live) return follow();
    return failure(name_ + ": inconsistent segment: " + std::to_string(failed_) + " reads in a row gave no pose at " +
                   "sequence " + std::to_string(next_) + " (published " + std::to_string(newest) + ")");
  }

  // The writer stopped, died or was replaced: end, or reattach to its successor.
  int follow() {
    const SegmentStatus s = reader_.check();
    if (s == SegmentStatus::Live) return -1;
    if (s == SegmentStatus::Stopped) return 0;
    std::fprintf(stderr, "mcslam-shm-echo: %s: %s (writer pid %lld); waiting up to %g s for a new segment\n",
                 name_.c_str(), mcslam::pose::segmentStatusName(s), static_cast<long long>(reader_.writerPid()),
                 wait_s_);
    std::string error;
    if (!attach(reader_, name_, wait_s_, true, error)) return failure(error);
    std::fprintf(stderr, "mcslam-shm-echo: %s: reattached (writer pid %lld)\n", name_.c_str(),
                 static_cast<long long>(reader_.writerPid()));
    next_ = firstSequence(reader_);
    failed_ = 0;
    missed_from_ = 0;
    return -1;
  }

  void reportMissed() {
    if (missed_from_ == 0) return;
    std::fprintf(stderr, "mcslam-shm-echo: missed poses %llu..%llu (reader too slow)\n",
                 static_cast<unsigned long long>(missed_from_), static_cast<unsigned long long>(next_ - 1));
    missed_from_ = 0;
  }

  int printLatest() {
    mcslam::pose::PoseRecord r;
    if (reader_.readLatest(r) != ReadStatus::Ok) return failure("no pose yet");
    mcslam::tools::printPose(r, stdout);
    return 0;
  }

  static int failure(const std::string& why) {
    std::fprintf(stderr, "mcslam-shm-echo: %s\n", why.c_str());
    return 1;
  }

  std::string name_;
  double wait_s_;
  PoseShmReader reader_;
  uint64_t next_ = 1;
  uint64_t missed_from_ = 0;  // first sequence of a gap not yet reported, 0 = none
  long long printed_ = 0;
  long long polls_ = 0;
  int failed_ = 0;
};
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-shm-echo: print the poses of mcslamd's shared-memory segment"};
  std::string name = "/mcslam_pose";
  long long count = 0;
  double wait_s = 10;
  bool latest = false;
  app.add_option("--name", name, "Segment name (publish.shm.name)")->capture_default_str();
  app.add_option("--count", count, "Exit after this many poses (0 = until the writer stops or Ctrl-C)");
  app.add_option("--wait", wait_s,
                 "Seconds to wait for the segment to appear, and for a new one after the writer died or was replaced")
      ->capture_default_str();
  app.add_flag("--latest", latest, "Print only the latest pose once and exit");
  CLI11_PARSE(app, argc, argv);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  return Echo(name, wait_s).run(count, latest);
}
