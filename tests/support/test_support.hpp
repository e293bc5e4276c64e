#pragma once
// Helpers shared by the tests.
#include <sys/types.h>

#include <filesystem>
#include <string>

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

// Forks a child that receives SIGKILL when the test process ends, however it ends (a ctest timeout included), so
// that no daemon or fake camera outlives its test. Returns fork()'s value.
pid_t forkDyingWithParent();

}  // namespace mcslam::test
