#include "realtime/scheduling.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

#include <spdlog/spdlog.h>

namespace mcslam::platform {

void nameThisThread(const char* name) {
  char shortName[16];
  std::strncpy(shortName, name, sizeof(shortName) - 1);
  shortName[sizeof(shortName) - 1] = '\0';
  pthread_setname_np(pthread_self(), shortName);
}

std::string setRealtimePriority(int priority) {
  if (priority <= 0) return {};
  sched_param p{};
  p.sched_priority = priority;
  const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
  return rc == 0 ? std::string() : std::string("SCHED_FIFO ") + std::to_string(priority) + ": " + std::strerror(rc);
}

std::string useBatchScheduling() {
  const sched_param p{};  // SCHED_BATCH has no priority: 0
  const int rc = pthread_setschedparam(pthread_self(), SCHED_BATCH, &p);
  return rc == 0 ? std::string() : std::string("SCHED_BATCH: ") + std::strerror(rc);
}

void setUpBackgroundThread() {
  if (const std::string why = useBatchScheduling(); !why.empty())
    spdlog::warn("background thread: {}; it keeps the normal scheduling", why);
}

std::string lockAllMemory() {
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  return std::string("mlockall: ") + std::strerror(errno);
}

std::string pinThisThread(int cpu) {
  if (cpu < 0) return {};
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
  return rc == 0 ? std::string() : "CPU " + std::to_string(cpu) + ": " + std::strerror(rc);
}

std::string restrictToCpus(const std::vector<int>& cpus) {
  if (cpus.empty()) return {};
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) CPU_SET(cpu, &set);
  const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
  return rc == 0 ? std::string() : std::strerror(rc);
}

}  // namespace mcslam::platform
