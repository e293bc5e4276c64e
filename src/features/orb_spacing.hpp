#pragma once
// Spreads the chosen corners over the image by a minimum spacing, strongest first.
//
// Why not ORB-SLAM's "best corner of each grid cell": the cells are fixed in the image, so when the
// view rotates or zooms they cut the scene differently and each view keeps different corners, which then
// have no partner in the other view (docs/benchmarks/orb.md). A minimum spacing depends only on distances, so it picks
// the same corners in both views (up to the budget's edge), while still keeping features away from each other.
#include <span>
#include <vector>

#include "orb_grid.hpp"

namespace mcslam::orb_detail {

class SpacedSelector {
 public:
  SpacedSelector(int max_corners, int max_width, int max_height);

  // Takes corners strongest first, skipping those closer than `spacing` to a corner already taken;
  // if the budget is not met, passes at half the spacing and then without spacing fill it.
  // Writes up to `budget` corners to out, returns how many.
  int select(std::span<const Corner> corners, const Rect& region, float spacing, int budget, Corner* out);

 private:
  bool farFromTaken(const Corner& c, const Corner* taken, float spacing) const;
  void sortByScore(std::span<const Corner> corners);  // into order_
  static constexpr int kScoreLevels = 256;            // integer scores below this take the counting sort

  int max_width_, max_height_;
  std::vector<int> order_;        // corner indices, strongest first
  std::vector<int> bucket_head_;  // taken corners by bucket (linked lists through next_)
  std::vector<int> next_;
  std::vector<unsigned char> used_;
  int bucket_size_ = 1, bucket_cols_ = 0, bucket_rows_ = 0;
  int origin_x_ = 0, origin_y_ = 0;
};

}  // namespace mcslam::orb_detail
