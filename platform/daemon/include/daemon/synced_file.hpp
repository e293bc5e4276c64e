#pragma once
// Writing a small file so that it is on disk afterwards, whole or not at all: the text goes to
// "<path>.tmp", which is fsynced and renamed over <path>, then the folder is fsynced. For the files
// written once at the end of a run (the refined extrinsics), where a power cut must not leave half a file.
#include <string>

namespace mcslam::platform {

// False (with the reason in *error) when a step failed; <path> then still holds its previous content.
bool writeFileSynced(const std::string& path, const std::string& text, std::string* error);

}  // namespace mcslam::platform
