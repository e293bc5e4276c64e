#pragma once
// The descriptors a vocabulary is trained on: ORB (the pipeline's extractor and options) of the images of
// datasets (every n-th rig frame, every camera) and of folders of image files.
#include <cstdint>
#include <string>
#include <vector>

#include "mcslam/features/orb_extractor.hpp"

namespace mcslam::places_tool {

struct TrainingSet {
  std::vector<Descriptor> descriptors;
  std::vector<uint64_t> image_offsets{0};  // image i: descriptors [offsets[i], offsets[i + 1])
  std::vector<std::string> sources;        // one line per input: what it gave
};

class TrainingSetBuilder {
 public:
  explicit TrainingSetBuilder(const OrbOptions& orb) : orb_(orb) {}
  // Every `every`-th rig frame of the dataset at `dir`, each camera an image. Throws InputError.
  void addDataset(const std::string& dir, int every);
  // Every `every`-th image file of the folder (any format readGreyImageFile reads), in name order.
  void addImageFolder(const std::string& dir, int every);
  TrainingSet take() { return std::move(set_); }

 private:
  void addImage(const ImageView& image);
  OrbExtractor& extractorFor(int width, int height);

  OrbOptions orb_;
  std::vector<OrbExtractor> extractors_;
  FeatureSet features_;
  TrainingSet set_;
};

}  // namespace mcslam::places_tool
