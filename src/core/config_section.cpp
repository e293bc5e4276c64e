#include "mcslam/core/config_section.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "mcslam/core/error.hpp"

namespace mcslam {

namespace {

// Walks the parsed tree once per node. yaml-cpp makes an alias the very node its anchor names, so the tree is a
// graph: a collection reached again through an alias was checked already (a file whose aliases would expand
// exponentially stays linear), and one reached inside itself is a loop, which no reader of the tree could finish.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::string& source) : source_(source) {}

  void check(const YAML::Node& node, const std::string& path) {
    if (!node.IsMap() && !node.IsSequence()) return;
    const int at = node.Mark().pos;  // distinct for every collection of the text
    if (open_.count(at))
      throw InputError(source_ + ": line " + std::to_string(node.Mark().line + 1) + ": " +
                       (path.empty() ? std::string("the document") : path) +
                       ": an alias refers to a node that contains it (a loop)");
    if (!done_.insert(at).second) return;
    open_.insert(at);
    if (node.IsSequence()) {
      for (std::size_t i = 0; i < node.size(); ++i) check(node[i], path + "[" + std::to_string(i) + "]");
    } else {
      checkMap(node, path);
    }
    open_.erase(at);
  }

 private:
  void checkMap(const YAML::Node& node, const std::string& path) {
    std::unordered_map<std::string, int> seen;  // key -> line
    for (const auto& entry : node) {
      const int line = entry.first.Mark().line + 1;
      if (entry.first.IsMap() || entry.first.IsSequence())  // no file of ours has them; readers take keys as words
        throw InputError(source_ + ": line " + std::to_string(line) + ": " + (path.empty() ? "the document" : path) +
                         ": a key must be a word, got a " + (entry.first.IsMap() ? "map" : "list"));
      const std::string key = entry.first.Scalar();
      const std::string key_path = path.empty() ? key : path + "." + key;
      const auto [first, added] = seen.emplace(key, line);
      if (!added)
        throw InputError(source_ + ": line " + std::to_string(line) + ": " + key_path +
                         ": appears twice in one map (first at line " + std::to_string(first->second) + ")");
      check(entry.second, key_path);
    }
  }

  const std::string& source_;
  std::unordered_set<int> done_;
  std::unordered_set<int> open_;  // the collections being walked (this one and its ancestors)
};

}  // namespace

YAML::Node parseYamlText(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": not valid YAML at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  DuplicateKeyCheck(source).check(root, "");
  return root;
}

ConfigSection::ConfigSection(const YAML::Node& node, std::string path, std::string source)
    : node_(node), path_(std::move(path)), source_(std::move(source)) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    throw InputError(source_ + ": " + (path_.empty() ? std::string("configuration") : path_) +
                     ": must be a map of keys");
  }
}

void ConfigSection::fail(const char* key, const std::string& what) const {
  throw InputError(source_ + ": " + keyPath(key) + ": " + what);
}

bool ConfigSection::has(const char* key) const { return node_ && node_.IsMap() && node_[key]; }

YAML::Node ConfigSection::scalar(const char* key, const char* expected) {
  known_.emplace_back(key);
  if (!has(key)) return YAML::Node(YAML::NodeType::Undefined);  // a default Node() is a *defined* null
  const YAML::Node n = node_[key];
  if (!n.IsScalar()) fail(key, std::string("must be ") + expected + ", got a " + (n.IsMap() ? "map" : "list"));
  return n;
}

namespace {
template <typename T>
std::string range(T min, T max) {
  std::ostringstream os;
  os << "[" << min << ", " << max << "]";
  return os.str();
}
}  // namespace

void ConfigSection::read(const char* key, int& value, int min, int max) {
  const YAML::Node n = scalar(key, "an integer");
  if (!n) return;
  long long v = 0;
  if (!YAML::convert<long long>::decode(n, v) || v < min || v > max) {
    fail(key, "must be an integer in " + range(min, max) + ", got '" + n.Scalar() + "'");
  }
  value = static_cast<int>(v);
}

void ConfigSection::read(const char* key, double& value, double min, double max) {
  const YAML::Node n = scalar(key, "a number");
  if (!n) return;
  double v = 0;
  if (!YAML::convert<double>::decode(n, v) || !std::isfinite(v) || v < min || v > max) {
    fail(key, "must be a number in " + range(min, max) + ", got '" + n.Scalar() + "'");
  }
  value = v;
}

void ConfigSection::read(const char* key, float& value, double min, double max) {
  double v = value;
  read(key, v, min, max);
  value = static_cast<float>(v);
}

void ConfigSection::read(const char* key, bool& value) {
  const YAML::Node n = scalar(key, "true or false");
  if (!n) return;
  bool v = false;
  if (!YAML::convert<bool>::decode(n, v)) fail(key, "must be true or false, got '" + n.Scalar() + "'");
  value = v;
}

void ConfigSection::read(const char* key, std::string& value, const std::vector<std::string>& allowed) {
  const YAML::Node n = scalar(key, "a word");
  if (!n) return;
  const std::string v = n.Scalar();
  if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    fail(key, "must be one of " + list + ", got '" + v + "'");
  }
  value = v;
}

void ConfigSection::read(const char* key, std::vector<double>& value, std::size_t count) {
  known_.emplace_back(key);
  if (!has(key)) return;
  const YAML::Node n = node_[key];
  if (!n.IsSequence() || (count && n.size() != count)) {
    fail(key,
         count ? "must be a list of " + std::to_string(count) + " numbers" : std::string("must be a list of numbers"));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    double v = 0;
    if (!n[i].IsScalar() || !YAML::convert<double>::decode(n[i], v) || !std::isfinite(v)) {
      fail(key, "entry " + std::to_string(i) + " is not a number");
    }
    out.push_back(v);
  }
  value = out;
}

ConfigSection ConfigSection::child(const char* key) {
  known_.emplace_back(key);
  if (!has(key)) return ConfigSection(YAML::Node(), keyPath(key), source_);
  const YAML::Node n = node_[key];
  if (!n.IsNull() && !n.IsMap()) fail(key, "must be a map of keys");
  return ConfigSection(n, keyPath(key), source_);
}

void ConfigSection::finish() const {
  if (!node_ || !node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string k = kv.first.as<std::string>();
    if (std::find(known_.begin(), known_.end(), k) == known_.end()) {
      std::string list;
      for (const auto& a : known_) list += (list.empty() ? "" : ", ") + a;
      throw InputError(source_ + ": " + keyPath(k.c_str()) + ": unknown key (known here: " + list + ")");
    }
  }
}

}  // namespace mcslam
