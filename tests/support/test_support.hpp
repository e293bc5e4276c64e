#pragma once
// Helpers shared by the tests.
#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace mcslam::test {

// tests/data/<relative>
std::string dataPath(const std::string& relative);
// build/bin/<program>
std::string binPath(const std::string& program);

// A fresh temporary folder, removed when the object goes out of scope.
class TempDir {
 public:
  explicit TempDir(const std::string& tag = "mcslam");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// Writes text to a file (creating folders); returns the path.
std::string writeFile(const std::string& path, const std::string& text);
// The whole file as bytes (empty when it cannot be read).
std::string readFile(const std::string& path);

// Runs a shell command, returns its exit code; stdout+stderr go to *output when given.
int runCommand(const std::string& command, std::string* output = nullptr);

// build/test-cache/<name>, made once by `fill` (given a fresh folder to fill, returns whether it succeeded) and
// kept for the test processes that follow: ctest runs each test case in its own process, and making the data
// (rendering) can take longer than the checks. A half-written folder is never taken for a finished one, and of two
// processes making it at once, one's folder is kept. An empty string when `fill` failed.
std::string cachedFolder(const std::string& name, const std::function<bool(const std::string& folder)>& fill);

// The folder `mcslam-sim <arguments> --out FOLDER` writes, made once (cachedFolder). The key is the arguments, the
// contents of `input_files` (paths that appear in the arguments, so that a file written to a temporary folder
// still finds its rendering) and the simulator's build time, so a rebuilt simulator renders again. On failure
// returns an empty string and mcslam-sim's output in *output.
std::string cachedRender(const std::string& arguments, const std::vector<std::string>& input_files = {},
                         std::string* output = nullptr);

// A UDP socket bound to `address` (IPv4, host byte order: INADDR_LOOPBACK, INADDR_ANY) on a port the kernel
// picks, whose receives give up after `timeout_ms`, with a receive buffer of `buffer_bytes` (0: the system's);
// closed with the object. fd() < 0 when it could not be made.
class UdpReceiver {
 public:
  UdpReceiver(uint32_t address, int timeout_ms, int buffer_bytes = 0);
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;
  int fd() const { return fd_; }
  int port() const { return port_; }

 private:
  int fd_ = -1;
  int port_ = 0;
};

// Forks a child that receives SIGKILL when the test process ends, however it ends (a ctest timeout included), so
// that no daemon or fake camera outlives its test. Returns fork()'s value.
pid_t forkDyingWithParent();

}  // namespace mcslam::test
