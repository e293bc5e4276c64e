#pragma once
// Little-endian binary files (vocabulary, map): a writer that appends to a buffer the caller sized, and a reader
// that checks every read against the end, so that a truncated or foreign file gives an error naming the file and
// the field instead of reading past the end.
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "mcslam/core/error.hpp"

namespace mcslam {

class ByteWriter {
 public:
  explicit ByteWriter(std::string& out) : out_(out) {}
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    putBytes(&value, sizeof(T));
  }
  void putBytes(const void* data, std::size_t size) { out_.append(static_cast<const char*>(data), size); }
  std::size_t size() const { return out_.size(); }

 private:
  std::string& out_;
};

class ByteReader {
 public:
  // `name` (the file) starts every error message.
  ByteReader(std::string_view bytes, std::string name) : bytes_(bytes), name_(std::move(name)) {}
  template <class T>
  T take(const char* field) {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    takeBytes(&value, sizeof(T), field);
    return value;
  }
  void takeBytes(void* out, std::size_t size, const char* field) {
    if (size > remaining())
      fail(std::string("truncated: the file ends at byte ") + std::to_string(bytes_.size()) + " in " + field);
    std::memcpy(out, bytes_.data() + at_, size);
    at_ += size;
  }
  std::size_t offset() const { return at_; }
  std::size_t remaining() const { return bytes_.size() - at_; }
  const std::string& name() const { return name_; }
  // Throws InputError "<name>: <what>".
  [[noreturn]] void fail(const std::string& what) const { throw InputError(name_ + ": " + what); }

 private:
  std::string_view bytes_;
  std::string name_;
  std::size_t at_ = 0;
};

// The whole file, refused (InputError naming it and `what` it should be) when it is missing, not a regular file or
// larger than `max_bytes`.
std::string readFileBounded(const std::string& path, std::size_t max_bytes, const std::string& what);

}  // namespace mcslam
