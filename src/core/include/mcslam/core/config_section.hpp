#pragma once
// Strict reading of YAML configuration sections: every key is type- and range-checked, an absent key
// keeps its default, and finish() rejects keys nobody asked for. Errors name the file and the full
// key path ("mcslamd.yaml: slam.orb.max_features: must be an integer in [16, 20000], got 'many'").
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace mcslam {

// Parses a configuration or calibration file's text: InputError naming `source` and the line for YAML that does not
// parse, and for a key that appears twice in one map (YAML parsers keep one of them silently, and the file would
// not mean what it seems to say).
YAML::Node parseYamlText(const std::string& text, const std::string& source);

class ConfigSection {
 public:
  // `path` is the key path of this section ("" for the root), `source` the file name.
  ConfigSection(const YAML::Node& node, std::string path, std::string source);

  void read(const char* key, int& value, int min, int max);
  void read(const char* key, double& value, double min, double max);
  void read(const char* key, float& value, double min, double max);
  void read(const char* key, bool& value);
  // One of `allowed` (when not empty).
  void read(const char* key, std::string& value, const std::vector<std::string>& allowed = {});
  // A list of numbers of exactly `count` entries (count 0: any length).
  void read(const char* key, std::vector<double>& value, std::size_t count);

  bool has(const char* key) const;
  // A nested map (an empty section when absent). Throws when the key holds something else.
  ConfigSection child(const char* key);
  // Throws InputError for every key of this section that was never read.
  void finish() const;

  const std::string& source() const { return source_; }
  std::string keyPath(const char* key) const { return path_.empty() ? key : path_ + "." + key; }
  [[noreturn]] void fail(const char* key, const std::string& what) const;

 private:
  YAML::Node scalar(const char* key, const char* expected);

  YAML::Node node_;
  std::string path_;
  std::string source_;
  std::vector<std::string> known_;
};

}  // namespace mcslam
