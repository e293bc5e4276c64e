#pragma once
// Minimal streaming JSON writer for the tools' --json output (no JSON library in our stack).
// Usage: JsonWriter j(os); j.beginObject(); j.key("a").value(1.0); j.endObject();
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

namespace mcslam {

class JsonWriter {
 public:
  explicit JsonWriter(std::ostream& os, bool pretty = true) : os_(os), pretty_(pretty) {}

  JsonWriter& beginObject() { return open('{'); }
  JsonWriter& endObject() { return close('}'); }
  JsonWriter& beginArray() { return open('['); }
  JsonWriter& endArray() { return close(']'); }

  JsonWriter& key(const std::string& k) {
    separate();
    writeString(k);
    os_ << (pretty_ ? ": " : ":");
    after_key_ = true;
    return *this;
  }
  JsonWriter& value(double v) {
    separate();
    if (!std::isfinite(v)) {
      os_ << "null";
    } else {
      char buf[32];
      std::snprintf(buf, sizeof(buf), "%.10g", v);
      os_ << buf;
    }
    return *this;
  }
  JsonWriter& value(int v) { return integer(v); }
  JsonWriter& value(long v) { return integer(v); }
  JsonWriter& value(long long v) { return integer(v); }
  JsonWriter& value(unsigned v) { return integer(static_cast<long long>(v)); }
  JsonWriter& value(unsigned long v) { return integer(static_cast<long long>(v)); }
  JsonWriter& value(unsigned long long v) { return integer(static_cast<long long>(v)); }
  JsonWriter& value(bool v) {
    separate();
    os_ << (v ? "true" : "false");
    return *this;
  }
  JsonWriter& value(const std::string& s) {
    separate();
    writeString(s);
    return *this;
  }
  JsonWriter& value(const char* s) { return value(std::string(s)); }
  template <typename Vec>
  JsonWriter& vector(const Vec& v, int n) {
    beginArray();
    for (int i = 0; i < n; ++i) value(static_cast<double>(v[i]));
    return endArray();
  }
  JsonWriter& null() {
    separate();
    os_ << "null";
    return *this;
  }

 private:
  JsonWriter& integer(long long v) {
    separate();
    os_ << v;
    return *this;
  }
  JsonWriter& open(char c) {
    separate();
    os_ << c;
    first_.push_back(true);
    return *this;
  }
  JsonWriter& close(char c) {
    const bool empty = first_.back();
    first_.pop_back();
    if (pretty_ && !empty) newline();
    os_ << c;
    if (first_.empty()) os_ << (pretty_ ? "\n" : "");
    return *this;
  }
  void separate() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (first_.empty()) return;
    if (!first_.back()) os_ << ',';
    first_.back() = false;
    if (pretty_) newline();
  }
  void newline() {
    os_ << '\n';
    for (std::size_t i = 0; i < first_.size(); ++i) os_ << "  ";
  }
  void writeString(const std::string& s) {
    os_ << '"';
    for (unsigned char c : s) {
      switch (c) {
        case '"': os_ << "\\\""; break;
        case '\\': os_ << "\\\\"; break;
        case '\n': os_ << "\\n"; break;
        case '\t': os_ << "\\t"; break;
        case '\r': os_ << "\\r"; break;
        default:
          if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof(buf), "\\u%04x", c);
            os_ << buf;
          } else {
            os_ << c;
          }
      }
    }
    os_ << '"';
  }

  std::ostream& os_;
  bool pretty_;
  bool after_key_ = false;
  std::vector<bool> first_;
};

}  // namespace mcslam
