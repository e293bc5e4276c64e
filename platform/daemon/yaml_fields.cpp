#include "daemon/yaml_fields.hpp"

#include <cmath>
#include <cstdlib>

#include "mcslam/core/error.hpp"

namespace mcslam::platform {

namespace {
std::string scalarText(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "nothing";
}
}  // namespace

YamlFields::YamlFields(const YAML::Node& node, std::string path, std::string file)
    : node_(node), path_(std::move(path)), file_(std::move(file)) {
  if (node_ && !node_.IsNull() && !node_.IsMap())
    throw InputError(file_ + ": " + (path_.empty() ? std::string("the document") : "'" + path_ + "'") +
                     " must be a map, got " + scalarText(node_));
}

void YamlFields::fail(const char* key, const std::string& what) const {
  throw InputError(file_ + ": " + keyName(key) + ": " + what);
}

void YamlFields::allowOnly(std::initializer_list<const char*> allowed) const {
  if (!node_ || !node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string k = kv.first.as<std::string>();
    bool ok = false;
    std::string list;
    for (const char* a : allowed) {
      ok = ok || k == a;
      list += (list.empty() ? "" : ", ") + std::string(a);
    }
    if (!ok) throw InputError(file_ + ": " + keyName(k.c_str()) + ": unknown key (allowed here: " + list + ")");
  }
}

bool YamlFields::has(const char* key) const { return node_ && node_.IsMap() && node_[key] && !node_[key].IsNull(); }

std::string YamlFields::string(const char* key, const std::string& fallback) const {
  if (!has(key)) return fallback;
  const YAML::Node n = node_[key];
  if (!n.IsScalar()) fail(key, "expected a text value, got " + scalarText(n));
  return n.Scalar();
}

std::string YamlFields::requiredString(const char* key) const {
  if (!has(key)) fail(key, "missing (required)");
  const std::string s = string(key, "");
  if (s.empty()) fail(key, "must not be empty");
  return s;
}

double YamlFields::number(const char* key, double fallback) const {
  if (!has(key)) return fallback;
  const YAML::Node n = node_[key];
  double v = 0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
    fail(key, "expected a number, got " + scalarText(n));
  return v;
}

double YamlFields::positiveNumber(const char* key, double fallback) const {
  const double v = number(key, fallback);
  if (!(v > 0)) fail(key, "must be greater than 0, got " + std::to_string(v));
  return v;
}

long long YamlFields::integer(const char* key, long long fallback, long long min, long long max) const {
  if (!has(key)) return fallback;
  const YAML::Node n = node_[key];
  long long v = 0;
  if (!n.IsScalar() || !YAML::convert<long long>::decode(n, v)) fail(key, "expected an integer, got " + scalarText(n));
  if (v < min || v > max)
    fail(key, "must be in [" + std::to_string(min) + ", " + std::to_string(max) + "], got " + std::to_string(v));
  return v;
}

uint32_t YamlFields::capacity(const char* key, uint32_t fallback, uint32_t max) const {
  if (has(key)) {
    const YAML::Node n = node_[key];
    long long v = 0;
    if (!n.IsScalar() || !YAML::convert<long long>::decode(n, v))
      fail(key, "expected an integer capacity, got " + scalarText(n));
    if (v < 1) fail(key, "a capacity must be at least 1, got " + std::to_string(v));
  }
  return static_cast<uint32_t>(integer(key, fallback, 1, max));
}

bool YamlFields::boolean(const char* key, bool fallback) const {
  if (!has(key)) return fallback;
  const YAML::Node n = node_[key];
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) fail(key, "expected true or false, got " + scalarText(n));
  return v;
}

std::string YamlFields::choice(const char* key, const std::string& fallback,
                               std::initializer_list<const char*> options) const {
  const std::string v = string(key, fallback);
  std::string list;
  for (const char* o : options) {
    if (v == o) return v;
    list += (list.empty() ? "" : ", ") + std::string(o);
  }
  fail(key, "'" + v + "' is not one of: " + list);
}

std::vector<std::string> YamlFields::stringList(const char* key) const {
  std::vector<std::string> out;
  if (!has(key)) return out;
  const YAML::Node n = node_[key];
  if (!n.IsSequence()) fail(key, "expected a list, got " + scalarText(n));
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar()) fail(key, "item " + std::to_string(i) + " must be a text value, got " + scalarText(n[i]));
    out.push_back(n[i].Scalar());
  }
  return out;
}

unsigned YamlFields::permissions(const char* key, unsigned fallback) const {
  if (!has(key)) return fallback;
  const std::string s = string(key, "");
  char* end = nullptr;
  const unsigned long v = std::strtoul(s.c_str(), &end, 8);
  if (s.empty() || *end != '\0' || v > 0777) fail(key, "expected octal permissions such as \"0640\", got '" + s + "'");
  return static_cast<unsigned>(v);
}

YamlFields YamlFields::child(const char* key) const {
  return YamlFields(has(key) ? node_[key] : YAML::Node(YAML::NodeType::Map), keyName(key), file_);
}

}  // namespace mcslam::platform
