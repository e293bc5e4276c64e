#include "test_support.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <stdexcept>

namespace mcslam::test {

std::string dataPath(const std::string& relative) { return std::string(MCSLAM_TEST_DATA_DIR) + "/" + relative; }
std::string binPath(const std::string& program) { return std::string(MCSLAM_BIN_DIR) + "/" + program; }

TempDir::TempDir(const std::string& tag) {
  std::random_device rd;
  const auto base = std::filesystem::temp_directory_path();
  for (int attempt = 0; attempt < 100; ++attempt) {
    auto candidate = base / (tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    if (std::filesystem::create_directories(candidate)) {
      path_ = candidate;
      return;
    }
  }
  throw std::runtime_error("cannot create a temporary folder");
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string writeFile(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  return path;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

int runCommand(const std::string& command, std::string* output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buf;
  std::string out;
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
  const int status = ::pclose(pipe);
  if (output) *output = out;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

namespace {

uint64_t fnv1a(const std::string& text, uint64_t hash = 14695981039346656037ull) {
  for (const unsigned char c : text) hash = (hash ^ c) * 1099511628211ull;
  return hash;
}

}  // namespace

std::string cachedFolder(const std::string& name, const std::function<bool(const std::string& folder)>& fill) {
  namespace fs = std::filesystem;
  const fs::path cache = fs::path(MCSLAM_BIN_DIR).parent_path() / "test-cache";
  const fs::path dir = cache / name;
  if (fs::exists(dir / "complete")) return dir.string();
  std::error_code ec;
  const fs::path tmp = cache / (name + ".tmp" + std::to_string(::getpid()));
  fs::remove_all(tmp, ec);
  fs::create_directories(tmp, ec);
  if (!fill(tmp.string())) {
    fs::remove_all(tmp, ec);
    return "";
  }
  writeFile((tmp / "complete").string(), name + "\n");
  fs::rename(tmp, dir, ec);  // another test process may have won the race: then use its folder
  if (ec) fs::remove_all(tmp, ec);
  return dir.string();
}

std::string cachedRender(const std::string& arguments, const std::vector<std::string>& input_files,
                         std::string* output) {
  const std::string simulator = binPath("mcslam-sim");
  std::error_code ec;
  const auto built = std::filesystem::last_write_time(simulator, ec);
  std::string key = arguments;
  for (const std::string& file : input_files) {
    const std::size_t at = key.find(file);
    if (at != std::string::npos) key.replace(at, file.size(), std::to_string(fnv1a(readFile(file))));
  }
  key += ec ? std::string("unknown") : std::to_string(built.time_since_epoch().count());
  return cachedFolder("render-" + std::to_string(fnv1a(key)), [&](const std::string& folder) {
    return runCommand(simulator + " " + arguments + " --out " + folder, output) == 0;
  });
}

UdpReceiver::UdpReceiver(uint32_t address, int timeout_ms, int buffer_bytes) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) return;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(address);
  socklen_t len = sizeof(a);
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 ||
      ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    ::close(fd_);
    fd_ = -1;
    return;
  }
  port_ = ntohs(a.sin_port);
  timeval tv{timeout_ms / 1000, (timeout_ms % 1000) * 1000};
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  if (buffer_bytes > 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buffer_bytes, sizeof(buffer_bytes));
}

UdpReceiver::~UdpReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

pid_t forkDyingWithParent() {
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(1);  // the parent ended before the request took effect
  }
  return pid;
}

}  // namespace mcslam::test
