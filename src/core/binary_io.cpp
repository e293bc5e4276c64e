#include "mcslam/core/binary_io.hpp"

#include <sys/stat.h>

#include <fstream>

namespace mcslam {

std::string readFileBounded(const std::string& path, std::size_t max_bytes, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw InputError(path + ": cannot open the " + what);
  if (!S_ISREG(st.st_mode)) throw InputError(path + ": not a regular file, so not a " + what);
  if (static_cast<std::size_t>(st.st_size) > max_bytes)
    throw InputError(path + ": " + std::to_string(st.st_size) + " bytes, more than any " + what + " (" +
                     std::to_string(max_bytes) + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the " + what);
  std::string bytes(static_cast<std::size_t>(st.st_size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<std::size_t>(in.gcount()) != bytes.size()) throw InputError(path + ": cannot read the whole file");
  return bytes;
}

}  // namespace mcslam
