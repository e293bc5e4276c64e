#include "mcslam/pipeline/dataset_frame.hpp"

#include <algorithm>

namespace mcslam {

void DatasetFrame::load(const Dataset& ds, std::size_t i) {
  const int cameras = ds.rig().size();
  if (static_cast<int>(views_.size()) != cameras) {
    images_.resize(cameras);
    views_.resize(cameras);
    present_.reset(new bool[cameras]);
  }
  error_.clear();
  ds.loadImages(i, images_, loaded_, &error_);
  for (int c = 0; c < cameras; ++c) {
    present_[c] = loaded_[c];
    views_[c] = loaded_[c] ? images_[c].view() : ImageView{};
  }
  t_ = ds.frames()[i].t;
  sequence_ = i;
}

void DatasetFrame::blacken() {
  for (std::size_t c = 0; c < images_.size(); ++c)
    if (loaded_[c]) std::fill_n(images_[c].data(), images_[c].width() * images_[c].height(), uint8_t{0});
}

RigFrameView DatasetFrame::view() const {
  RigFrameView v;
  v.t = t_;
  v.sequence = sequence_;
  v.cameras = static_cast<int>(views_.size());
  v.images = views_.data();
  v.present = present_.get();
  return v;
}

}  // namespace mcslam
