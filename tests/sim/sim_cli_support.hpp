#pragma once
// Running the built mcslam-sim (through the emulator in a cross build, test::binPath) and reading what it wrote.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include "test_support.hpp"

namespace mcslam::sim::testing {

// Runs mcslam-sim with `args` (in folder `cwd` when given); returns its exit code, stdout+stderr in *output.
inline int runSim(const std::string& args, std::string* output = nullptr, const std::string& cwd = "") {
  const std::string cd = cwd.empty() ? "" : "cd '" + cwd + "' && ";
  return test::runCommand(cd + test::binPath("mcslam-sim") + " " + args, output);
}

// Every file under dir (relative path -> bytes).
inline std::map<std::string, std::string> readTree(const std::filesystem::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    files[std::filesystem::relative(e.path(), dir).string()] =
        std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return files;
}

}  // namespace mcslam::sim::testing
