#pragma once
// Writing a file so that it is on disk afterwards, whole or not at all: the bytes go to "<path>.tmp", which is
// fsynced and renamed over <path>, then the folder is fsynced. A crash or power cut mid-write leaves the previous
// <path> as it was. For the files a robot relies on after a restart (refined extrinsics, the map, the vocabulary).
// A <path> that is a device, a pipe or a socket (/dev/stdout, a FIFO) is written to directly and left in place.
#include <string>
#include <string_view>

namespace mcslam {

// False (with the reason, naming the file, in *error) when a step failed; <path> then still holds its previous
// content and no "<path>.tmp" is left behind.
bool writeFileSynced(const std::string& path, std::string_view bytes, std::string* error);

// The names one file's synced writes use, worked out once: writing a file again and again (the daemon's map)
// then allocates nothing unless a step fails.
struct SyncedFileTarget {
  explicit SyncedFileTarget(const std::string& path);
  std::string path, tmp, folder;
};
bool writeFileSynced(const SyncedFileTarget& target, std::string_view bytes, std::string* error);

}  // namespace mcslam
