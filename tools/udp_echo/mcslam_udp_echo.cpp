// mcslam-udp-echo: receives mcslamd's UDP pose datagrams and prints them (same format as
// mcslam-shm-echo). Reports datagrams that are not pose records and gaps in the sequence.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "pose_print.hpp"

int main(int argc, char** argv) {
  CLI::App app{"mcslam-udp-echo: print the pose datagrams mcslamd sends"};
  std::string bind_address = "0.0.0.0";
  int port = 9870;
  long long count = 0;
  double timeout_s = 0;
  app.add_option("--bind", bind_address, "Local IPv4 address to listen on")->capture_default_str();
  app.add_option("--port", port, "UDP port (publish.udp.destinations)")->capture_default_str();
  app.add_option("--count", count, "Exit after this many poses (0 = forever)");
  app.add_option("--timeout", timeout_s, "Exit with status 1 when nothing arrives for this long (0 = wait forever)");
  CLI11_PARSE(app, argc, argv);

  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (::inet_pton(AF_INET, bind_address.c_str(), &addr.sin_addr) != 1 ||
      ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    std::fprintf(stderr, "mcslam-udp-echo: cannot listen on %s:%d: %s\n", bind_address.c_str(), port,
                 std::strerror(errno));
    return 1;
  }
  if (timeout_s > 0) {
    timeval tv{static_cast<time_t>(timeout_s),
               static_cast<suseconds_t>((timeout_s - static_cast<long>(timeout_s)) * 1e6)};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  }
  uint8_t buf[2048];
  long long printed = 0;
  uint64_t last = 0;
  while (count == 0 || printed < count) {
    const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      std::fprintf(stderr, "mcslam-udp-echo: nothing received for %.1f s\n", timeout_s);
      return 1;
    }
    mcslam::pose::PoseRecord r;
    const auto status = mcslam::pose::decodePacket(buf, static_cast<std::size_t>(n), r);
    if (status != mcslam::pose::DecodeStatus::Ok) {
      std::fprintf(stderr, "mcslam-udp-echo: ignored a %zd-byte datagram: %s\n", n,
                   mcslam::pose::decodeStatusName(status));
      continue;
    }
    if (last != 0 && r.sequence != last + 1)
      std::fprintf(stderr, "mcslam-udp-echo: gap: %llu after %llu\n", static_cast<unsigned long long>(r.sequence),
                   static_cast<unsigned long long>(last));
    last = r.sequence;
    mcslam::tools::printPose(r, stdout);
    ++printed;
  }
  ::close(fd);
  return 0;
}
