#include "repeating_textures.hpp"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace mcslam::test {

namespace {

constexpr int kSize = 512;  // the simulator's photo size: one copy covers 1.5 m of a face

// Per-element shade variation and sensor-like grain: real repeating surfaces are alike, not identical.
void grain(cv::Mat& img, cv::RNG& rng, double sigma) {
  cv::Mat noise(img.size(), CV_16S);
  rng.fill(noise, cv::RNG::NORMAL, 0, sigma);
  cv::Mat wide;
  img.convertTo(wide, CV_16S);
  wide += noise;
  wide.convertTo(img, CV_8U);
}

cv::Mat brick(cv::RNG& rng, int w, int h, int mortar) {
  cv::Mat img(kSize, kSize, CV_8U, cv::Scalar(200));
  for (int row = 0; row * h < kSize; ++row) {
    const int offset = (row % 2) * w / 2;
    for (int x = -offset; x < kSize; x += w) {
      const int shade = 90 + rng.uniform(-12, 13);
      cv::rectangle(img, cv::Rect(x + mortar / 2, row * h + mortar / 2, w - mortar, h - mortar), cv::Scalar(shade),
                    cv::FILLED);
    }
  }
  return img;
}

cv::Mat tiles(cv::RNG& rng, int period, int grout) {
  cv::Mat img(kSize, kSize, CV_8U, cv::Scalar(60));
  for (int y = 0; y < kSize; y += period) {
    for (int x = 0; x < kSize; x += period) {
      const int shade = 185 + rng.uniform(-8, 9);
      cv::rectangle(img, cv::Rect(x + grout, y + grout, period - 2 * grout, period - 2 * grout), cv::Scalar(shade),
                    cv::FILLED);
    }
  }
  return img;
}

cv::Mat checker(int period) {
  cv::Mat img(kSize, kSize, CV_8U);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) img.at<uint8_t>(y, x) = ((x / period + y / period) % 2) ? 200 : 50;
  }
  return img;
}

cv::Mat dots(int period, int radius) {
  cv::Mat img(kSize, kSize, CV_8U, cv::Scalar(190));
  for (int y = period / 2; y < kSize; y += period) {
    for (int x = period / 2; x < kSize; x += period) cv::circle(img, {x, y}, radius, cv::Scalar(40), cv::FILLED);
  }
  return img;
}

cv::Mat grid(int period, int line) {
  cv::Mat img(kSize, kSize, CV_8U, cv::Scalar(170));
  for (int p = 0; p < kSize; p += period) {
    cv::rectangle(img, cv::Rect(p, 0, line, kSize), cv::Scalar(30), cv::FILLED);
    cv::rectangle(img, cv::Rect(0, p, kSize, line), cv::Scalar(30), cv::FILLED);
  }
  return img;
}

// A small asymmetric motif (an L, a bar and a dot) repeated on a lattice, like a wallpaper or a facade.
cv::Mat motif(int px, int py) {
  cv::Mat img(kSize, kSize, CV_8U, cv::Scalar(175));
  for (int y = 0; y < kSize; y += py) {
    for (int x = 0; x < kSize; x += px) {
      cv::rectangle(img, cv::Rect(x + 6, y + 6, 6, py / 2), cv::Scalar(35), cv::FILLED);
      cv::rectangle(img, cv::Rect(x + 6, y + 6 + py / 2 - 6, px / 3, 6), cv::Scalar(35), cv::FILLED);
      cv::rectangle(img, cv::Rect(x + px / 2 + 4, y + 8, px / 4, 5), cv::Scalar(90), cv::FILLED);
      cv::circle(img, {x + 3 * px / 4, y + 3 * py / 4}, 4, cv::Scalar(60), cv::FILLED);
    }
  }
  return img;
}

}  // namespace

std::string writeRepeatingTextures(const std::string& dir, unsigned seed) {
  std::filesystem::create_directories(dir);
  cv::RNG rng(seed);
  const std::pair<const char*, cv::Mat> textures[] = {
      {"brick_a", brick(rng, 64, 24, 4)},
      {"brick_b", brick(rng, 48, 20, 3)},
      {"tiles_a", tiles(rng, 64, 3)},
      {"tiles_b", tiles(rng, 40, 2)},
      {"checker", checker(32)},
      {"dots", dots(36, 7)},
      {"grid", grid(44, 4)},
      {"motif", motif(56, 48)},
  };
  for (const auto& [name, image] : textures) {
    cv::Mat img = image.clone();
    grain(img, rng, 3.0);
    cv::imwrite(dir + "/" + name + ".png", img);
  }
  return dir;
}

}  // namespace mcslam::test
