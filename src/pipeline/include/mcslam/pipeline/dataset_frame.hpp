#pragma once
// One rig frame of a recorded dataset, decoded, in the form the pipeline takes (RigFrameView): what the offline
// tools feed to the front-end. Loading again reuses the images (an Image reallocates only when it grows).
#include <memory>
#include <string>
#include <vector>

#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/frame_processor.hpp"

namespace mcslam {

class DatasetFrame {
 public:
  // Loads rig frame i of `ds`. An unreadable image leaves its camera absent; error() says why.
  void load(const Dataset& ds, std::size_t i);
  // Valid until the next load() (and across a move: it points into this object's heap buffers).
  RigFrameView view() const;
  const std::string& error() const { return error_; }
  // Every loaded image becomes black (fault injection: a covered or dark rig; the cameras stay present).
  void blacken();

 private:
  std::vector<Image> images_;
  std::vector<bool> loaded_;
  std::vector<ImageView> views_;
  std::unique_ptr<bool[]> present_;
  std::string error_;
  Timestamp t_ = 0;
  uint64_t sequence_ = 0;
};

}  // namespace mcslam
