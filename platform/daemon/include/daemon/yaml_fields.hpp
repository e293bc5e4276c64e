#pragma once
// Strict reading of YAML configuration fields: every error names the file, the full key and the value.
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

namespace mcslam::platform {

// An enumerated setting's value and the name the configuration file gives it.
template <typename E>
struct NamedValue {
  const char* name;
  E value;
};

template <typename E, std::size_t N>
const char* nameOf(E value, const NamedValue<E> (&names)[N]) {
  for (const NamedValue<E>& n : names)
    if (n.value == value) return n.name;
  return "?";
}

class YamlFields {
 public:
  // `node` is the map at `path` ("" for the document root) of `file`.
  YamlFields(const YAML::Node& node, std::string path, std::string file);

  // Throws when the map has a key outside `allowed`, or is not a map.
  void allowOnly(std::initializer_list<const char*> allowed) const;
  bool has(const char* key) const;

  std::string string(const char* key, const std::string& fallback) const;
  std::string requiredString(const char* key) const;
  double number(const char* key, double fallback) const;
  double positiveNumber(const char* key, double fallback) const;
  long long integer(const char* key, long long fallback, long long min, long long max) const;
  // A capacity: an integer >= 1.
  uint32_t capacity(const char* key, uint32_t fallback, uint32_t max = 1u << 20) const;
  bool boolean(const char* key, bool fallback) const;
  std::string choice(const char* key, const std::string& fallback, std::initializer_list<const char*> options) const;
  // One of the names in `options`, as its value (the error lists the names).
  template <typename E, std::size_t N>
  E choice(const char* key, E fallback, const NamedValue<E> (&options)[N]) const {
    const std::string v = string(key, nameOf(fallback, options));
    std::string list;
    for (const NamedValue<E>& o : options) {
      if (v == o.name) return o.value;
      list += (list.empty() ? "" : ", ") + std::string(o.name);
    }
    fail(key, "'" + v + "' is not one of: " + list);
  }
  std::vector<std::string> stringList(const char* key) const;
  // File permissions: an octal string ("0640") or an integer written in octal (0640 parses as 640).
  unsigned permissions(const char* key, unsigned fallback) const;

  YamlFields child(const char* key) const;  // an absent child is an empty map
  YAML::Node node(const char* key) const { return node_[key]; }
  std::string keyName(const char* key) const { return path_.empty() ? key : path_ + "." + key; }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  [[noreturn]] void fail(const char* key, const std::string& what) const;

 private:
  YAML::Node node_;
  std::string path_;
  std::string file_;
};

}  // namespace mcslam::platform
