#include "training_set.hpp"

#include <algorithm>
#include <filesystem>

#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/image_file.hpp"

namespace mcslam::places_tool {

OrbExtractor& TrainingSetBuilder::extractorFor(int width, int height) {
  for (OrbExtractor& e : extractors_)
    if (e.maxWidth() == width && e.maxHeight() == height) return e;
  extractors_.emplace_back(orb_, width, height);
  return extractors_.back();
}

void TrainingSetBuilder::addImage(const ImageView& image) {
  if (features_.capacity() < orb_.max_features) features_.reserve(orb_.max_features);
  extractorFor(image.width, image.height).extract(image, features_);
  if (features_.count == 0) return;
  set_.descriptors.insert(set_.descriptors.end(), features_.descriptors.begin(),
                          features_.descriptors.begin() + features_.count);
  set_.image_offsets.push_back(set_.descriptors.size());
}

void TrainingSetBuilder::addDataset(const std::string& dir, int every) {
  const Dataset dataset = Dataset::open(dir);
  std::vector<Image> images;
  std::vector<bool> present;
  const std::size_t before = set_.image_offsets.size();
  for (std::size_t i = 0; i < dataset.size(); i += static_cast<std::size_t>(every)) {
    std::string error;
    dataset.loadImages(i, images, present, &error);
    if (!error.empty()) throw InputError(error);
    for (std::size_t c = 0; c < images.size(); ++c)
      if (present[c]) addImage(images[c].view());
  }
  set_.sources.push_back(dir + ": " + std::to_string(set_.image_offsets.size() - before) + " images");
}

void TrainingSetBuilder::addImageFolder(const std::string& dir, int every) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (entry.is_regular_file()) files.push_back(entry.path().string());
  if (ec) throw InputError(dir + ": cannot list the image folder: " + ec.message());
  std::sort(files.begin(), files.end());
  Image image;
  const std::size_t before = set_.image_offsets.size();
  for (std::size_t i = 0; i < files.size(); i += static_cast<std::size_t>(every)) {
    readGreyImageFile(files[i], image);
    addImage(image.view());
  }
  set_.sources.push_back(dir + ": " + std::to_string(set_.image_offsets.size() - before) + " images");
}

}  // namespace mcslam::places_tool
