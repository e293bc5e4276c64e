// ORB extraction against cv::ORB on identical input: one 720x540 image, 1000 features, one thread;
// and the five-camera rig frame through FeatureWorkers on 2 threads against cv::ORB run on the
// same five images with OpenCV's default threading.
//
// Input: the procedural textured frames of tests/features/orb_test_images.hpp (multi-scale texture,
// sharp-edged shapes, blobs, sensor noise), seeded, so every run sees the same pixels.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <vector>

#include "../features/orb_test_images.hpp"
#include "mcslam/features/feature_workers.hpp"
#include "mcslam/features/orb_extractor.hpp"

namespace {

using mcslam::FeatureSet;
using mcslam::Image;

constexpr int kWidth = 720, kHeight = 540, kFeatures = 1000, kCameras = 5;

const std::vector<Image>& rigImages() {
  static const std::vector<Image> images = [] {
    std::vector<Image> v;
    for (int c = 0; c < kCameras; ++c) v.push_back(mcslam::test::texturedFrame(kWidth, kHeight, 7 + c));
    return v;
  }();
  return images;
}

cv::Mat asMat(const Image& image) {
  return cv::Mat(image.height(), image.width(), CV_8U, const_cast<uint8_t*>(image.data()));
}

void OrbExtractMcslam(benchmark::State& state) {
  const Image& image = rigImages()[0];
  mcslam::OrbOptions options;
  options.max_features = kFeatures;
  mcslam::OrbExtractor extractor(options, kWidth, kHeight);
  FeatureSet out(kFeatures);
  for (auto _ : state) {
    extractor.extract(image.view(), out);
    benchmark::DoNotOptimize(out.count);
  }
  state.counters["features"] = out.count;
}

void OrbExtractCvOrb(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat image = asMat(rigImages()[0]);
  auto orb = cv::ORB::create(kFeatures);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["features"] = static_cast<double>(keypoints.size());
  cv::setNumThreads(-1);  // back to OpenCV's default for the other cases
}

void FeatureWorkers5CamsMcslam(benchmark::State& state) {
  mcslam::OrbOptions options;
  options.max_features = kFeatures;
  const std::vector<mcslam::ImageSize> sizes(kCameras, {kWidth, kHeight});
  mcslam::FeatureWorkers workers(options, sizes, 2);
  std::vector<mcslam::ImageView> views;
  for (const Image& image : rigImages()) views.push_back(image.view());
  std::vector<FeatureSet> out(kCameras, FeatureSet(kFeatures));
  const bool present[kCameras] = {true, true, true, true, true};
  for (auto _ : state) {
    workers.extract(views.data(), present, out.data());
    benchmark::DoNotOptimize(out[0].count);
  }
  int total = 0;
  for (const FeatureSet& set : out) total += set.count;
  state.counters["features"] = total;
}

void FeatureWorkers5CamsCvOrb(benchmark::State& state) {
  cv::setNumThreads(-1);
  std::vector<cv::Mat> images;
  for (const Image& image : rigImages()) images.push_back(asMat(image));
  auto orb = cv::ORB::create(kFeatures);
  std::vector<std::vector<cv::KeyPoint>> keypoints(kCameras);
  std::vector<cv::Mat> descriptors(kCameras);
  for (auto _ : state) {
    for (int c = 0; c < kCameras; ++c) orb->detectAndCompute(images[c], cv::noArray(), keypoints[c], descriptors[c]);
    benchmark::DoNotOptimize(descriptors[0].data);
  }
  size_t total = 0;
  for (const auto& k : keypoints) total += k.size();
  state.counters["features"] = static_cast<double>(total);
}

}  // namespace

BENCHMARK(OrbExtractMcslam)->Name("OrbExtract720x540/mcslam")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(OrbExtractCvOrb)->Name("OrbExtract720x540/cv_orb")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(FeatureWorkers5CamsMcslam)->Name("FeatureWorkers5Cams/mcslam")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(FeatureWorkers5CamsCvOrb)->Name("FeatureWorkers5Cams/cv_orb")->Unit(benchmark::kMillisecond)->UseRealTime();
