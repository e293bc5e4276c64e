#pragma once
// Internal: pieces shared by the dataset writers of dataset_export.cpp and kitti_export.cpp.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mcslam/dataset/dataset_export.hpp"

namespace mcslam::detail {

// Creates dir; throws InputError when it exists and is not an empty folder (nothing is ever overwritten).
void prepareOutputFolder(const std::string& dir);
void createFolder(const std::filesystem::path& dir);
void writeTextFile(const std::filesystem::path& path, const std::string& text);
// Hard link or copy of an image file; must_be_png re-encodes other formats to PNG.
void placeImage(const std::string& source, const std::filesystem::path& target, bool must_be_png);
// The ground-truth pose (body frame) of every rig frame, matched by time within the sync tolerance.
std::vector<std::optional<SE3>> groundTruthPerFrame(const Dataset& dataset);

// Throws InputError naming the camera when the rig is not one KITTI's calib.txt can describe.
void checkKittiRig(const Rig& rig);
void exportKitti(const Dataset& dataset, const std::filesystem::path& root, DatasetExportReport& report);

}  // namespace mcslam::detail
