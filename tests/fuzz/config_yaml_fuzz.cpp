// The strict YAML configuration reader (core/config_section.hpp): parseYamlText, then every key of the root map
// read through ConfigSection as each type a configuration asks for, and finish(). Documented outcome for bad
// input: mcslam::InputError (yaml-cpp's own exceptions must not escape).
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "mcslam/core/config_section.hpp"
#include "mcslam/core/error.hpp"

namespace {

using mcslam::ConfigSection;

// Reads `key` of `node` as one type; the reader's own checks decide whether it fits.
void readAs(const YAML::Node& node, const std::string& key, int type) {
  ConfigSection s(node, "root", "fuzz.yaml");
  const char* k = key.c_str();
  int i = 0;
  double d = 0;
  float f = 0;
  bool b = false;
  std::string w;
  std::vector<double> v;
  switch (type) {
    case 0: s.read(k, i, -1000, 1000); break;
    case 1: s.read(k, d, -1e9, 1e9); break;
    case 2: s.read(k, f, 0.0, 1.0); break;
    case 3: s.read(k, b); break;
    case 4: s.read(k, w, {"a", "b"}); break;
    case 5: s.read(k, v, 0); break;
    case 6: s.read(k, v, 3); break;
    default: s.child(k).finish(); break;
  }
  s.finish();
}

void readEveryKey(const YAML::Node& root) {
  if (!root.IsMap()) return;
  std::vector<std::string> keys;
  for (const auto& kv : root)
    if (kv.first.IsScalar()) keys.push_back(kv.first.Scalar());
  for (const std::string& key : keys) {
    for (int type = 0; type < 8; ++type) {
      try {
        readAs(root, key, type);
      } catch (const mcslam::InputError&) {
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  try {
    readEveryKey(mcslam::parseYamlText(mcslam::fuzz::text(data, size), "fuzz.yaml"));
  } catch (const mcslam::InputError&) {
  }
  return 0;
}
