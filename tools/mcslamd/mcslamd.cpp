// mcslamd: the onboard daemon (docs/daemon.md). Cameras or a replay in, poses out over shared memory
// and UDP, trajectory to the state directory; systemd Type=notify.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include "daemon/daemon_config.hpp"
#include "daemon/supervisor.hpp"
#include "mcslam/core/error.hpp"
#include "shm/pose_shm_writer.hpp"

int main(int argc, char** argv) {
  CLI::App app{"mcslamd: multi-camera visual SLAM daemon (poses over shared memory and UDP)"};
  std::string config_path, check_path;
  auto* run = app.add_option("--config", config_path, "Run with this configuration file");
  auto* check = app.add_option("--check-config", check_path, "Validate a configuration and print the effective one");
  run->excludes(check);
  check->excludes(run);
  CLI11_PARSE(app, argc, argv);
  if (config_path.empty() && check_path.empty()) {
    std::fprintf(stderr, "mcslamd: give --config FILE or --check-config FILE (see --help)\n");
    return 2;
  }
  // journald takes stdout; it adds its own time stamps but the milliseconds help reading latencies.
  auto logger = spdlog::stdout_logger_mt("mcslamd");
  logger->set_pattern("%H:%M:%S.%e %^%l%$ %v");
  spdlog::set_default_logger(logger);
  try {
    if (!check_path.empty()) {
      const auto config = mcslam::platform::loadDaemonConfig(check_path);
      std::cout << "# " << check_path << ": valid\n" << mcslam::platform::effectiveDaemonConfig(config);
      return 0;
    }
    const auto config = mcslam::platform::loadDaemonConfig(config_path);
    spdlog::set_level(spdlog::level::from_str(config.log_level));
    logger->flush_on(spdlog::level::trace);  // journald should see lines as they happen
    return mcslam::platform::runDaemon(config);
  } catch (const mcslam::InputError& e) {
    std::fprintf(stderr, "mcslamd: %s\n", e.what());
    std::fflush(stdout);
    return 2;
  } catch (const mcslam::platform::ResourceBusyError& e) {
    // Someone else holds what we need; unlike a bad configuration, a restart may find it released.
    std::fprintf(stderr, "mcslamd: %s\n", e.what());
    std::fflush(stdout);
    return 3;
  }
}
