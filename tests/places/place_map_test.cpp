// The place map: keyframes chained per segment, points sorted by vocabulary node, slots recycled and ids not,
// capacity honoured, nothing allocated after construction; a new unit of the odometry rescales the keyframes made in
// the old one: all of them while the unit was arbitrary, those since the estimate's window once it was known.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <vector>
#include "alloc_testing.hpp"

#include "mcslam/places/place_map.hpp"

namespace mcslam {
namespace {

PlacePoint pointAt(int32_t node, int64_t landmark) {
  PlacePoint p;
  p.node = node;
  p.landmark_id = landmark;
  p.p_k = Eigen::Vector3f(static_cast<float>(node), 0, 1);
  return p;
}

TEST(PlaceMap, KeyframesChainWithinTheirSegment) {
  PlaceMap map(8, 10);
  const int32_t s0 = map.createSegment(SE3());
  const int32_t s1 = map.createSegment(SE3(Mat3::Identity(), Vec3(1, 2, 3)));
  const int a = map.createKeyframe(s0, 1, 1, SE3(), SE3());
  const int b = map.createKeyframe(s1, 2, 2, SE3(), SE3());
  const int c = map.createKeyframe(s0, 3, 3, SE3(), SE3());
  EXPECT_EQ(map.keyframe(a).next, c);
  EXPECT_EQ(map.keyframe(c).previous, a);
  EXPECT_EQ(map.keyframe(b).previous, -1);
  EXPECT_EQ(map.keyframe(b).next, -1);
  EXPECT_EQ(map.segmentPose(s1).t, Vec3(1, 2, 3));
  EXPECT_EQ(map.newestKeyframe(), c);
  map.eraseKeyframe(c);
  EXPECT_EQ(map.keyframe(a).next, -1);
  EXPECT_EQ(map.newestKeyframe(), a);
  const int d = map.createKeyframe(s0, 4, 4, SE3(), SE3());
  EXPECT_EQ(d, c);                                    // the slot is recycled ...
  EXPECT_GT(map.keyframe(d).id, map.keyframe(b).id);  // ... the id is not
  EXPECT_EQ(map.keyframe(a).next, d);
  EXPECT_EQ(map.size(), 3);
}

// A robot's life can start more odometry maps than there are segments: with all taken, one left without
// keyframes is set up anew, and what continued it no longer does.
TEST(PlaceMap, ASegmentWithoutKeyframesCanBeReusedWhenAllAreTaken) {
  PlaceMap map(8, 10);
  for (int32_t s = 0; s < PlaceMap::kMaxSegments; ++s) ASSERT_EQ(map.createSegment(SE3(), true, s - 1), s);
  EXPECT_EQ(map.createSegment(SE3()), -1);
  const int a = map.createKeyframe(5, 1, 1, SE3(), SE3());
  EXPECT_TRUE(map.hasKeyframes(5));
  EXPECT_FALSE(map.hasKeyframes(7));
  const SE3 T_w_o(Mat3::Identity(), Vec3(4, 5, 6));
  map.reuseSegment(7, T_w_o, /*placed=*/false, /*continues=*/1023);
  EXPECT_EQ(map.segments(), PlaceMap::kMaxSegments);
  EXPECT_EQ(map.segmentPose(7).t, T_w_o.t);
  EXPECT_FALSE(map.placed(7));
  EXPECT_EQ(map.continuesFrom(7), 1023);
  EXPECT_EQ(map.continuesFrom(8), -1);  // it continued the segment that was 7
  EXPECT_EQ(map.continuesFrom(9), 8);
  map.eraseKeyframe(a);
  EXPECT_FALSE(map.hasKeyframes(5));
}

TEST(PlaceMap, PointsAreFoundByTheirNode) {
  PlaceMap map(2, 6);
  const int k = map.createKeyframe(map.createSegment(SE3()), 0, 0, SE3(), SE3());
  for (int32_t node : {7, 3, 7, 1, 3, 9}) EXPECT_TRUE(map.addPoint(k, pointAt(node, node * 10)));
  EXPECT_FALSE(map.addPoint(k, pointAt(2, 0)));  // full
  map.finishKeyframe(k);
  EXPECT_EQ(map.pointsOfNode(k, 7).size(), 2u);
  EXPECT_EQ(map.pointsOfNode(k, 3).size(), 2u);
  EXPECT_EQ(map.pointsOfNode(k, 9).size(), 1u);
  EXPECT_EQ(map.pointsOfNode(k, 4).size(), 0u);
  EXPECT_EQ(map.pointsOfNode(k, 10).size(), 0u);
  for (const PlacePoint& p : map.pointsOfNode(k, 3)) EXPECT_EQ(p.node, 3);
}

TEST(PlaceMap, AFullMapRefusesAKeyframeAndAllocatesNothing) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  PlaceMap map(3, 4);
  alloc::ThreadScope scope;
  const int32_t s = map.createSegment(SE3());
  for (int i = 0; i < 3; ++i) {
    const int k = map.createKeyframe(s, i, static_cast<uint64_t>(i), SE3(), SE3());
    ASSERT_GE(k, 0);
    for (int j = 0; j < 4; ++j) map.addPoint(k, pointAt(4 - j, j));
    map.finishKeyframe(k);
  }
  EXPECT_EQ(map.createKeyframe(s, 9, 9, SE3(), SE3()), -1);
  map.eraseKeyframe(1);
  EXPECT_EQ(map.createKeyframe(s, 9, 9, SE3(), SE3()), 1);
  EXPECT_EQ(scope.count(), 0u);
}

// Keyframes along x at `xs`, turned about z by `yaw_deg`, in one segment; returns their slots.
std::vector<int> chain(PlaceMap& map, const std::vector<double>& xs, const std::vector<double>& yaw_deg) {
  const int32_t s = map.createSegment(SE3());
  std::vector<int> slots;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const SE3 T(so3Exp(Vec3(0, 0, yaw_deg[i] * M_PI / 180)), Vec3(xs[i], 0, 0));
    slots.push_back(map.createKeyframe(s, static_cast<Timestamp>(i), i, T, T));
  }
  return slots;
}

// Where the rig lingered goes first; ends and the kept keyframes (loops') stay.
TEST(PlaceMap, TheLeastNeededKeyframeIsWhereTheRigLingered) {
  PlaceMap map(8, 1);
  const std::vector<int> k = chain(map, {0, 1, 2, 2.1, 2.2, 3, 4}, {0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(map.leastNeededKeyframe({}), k[3]);  // its neighbours are 0.2 m apart
  const std::vector<int64_t> kept{map.keyframe(k[3]).id};
  EXPECT_EQ(map.leastNeededKeyframe(kept), k[4]);  // 0.9 m, before the keyframe at 2 (1.1 m)
  PlaceMap two(2, 1);
  chain(two, {0, 5}, {0, 0});
  EXPECT_EQ(two.leastNeededKeyframe({}), -1);  // a segment's ends always stay
}

// A turn counts: of keyframes evenly spaced, the one whose neighbours face the same way goes.
TEST(PlaceMap, TurningMakesAKeyframeNeeded) {
  PlaceMap map(8, 1);
  const std::vector<int> k = chain(map, {0, 1, 2, 3, 4}, {0, 0, 0, 90, 90});
  EXPECT_EQ(map.leastNeededKeyframe({}), k[1]);
}

// Four keyframes 2 m apart along x in a segment placed 10 m up y; the third was bent 0.5 m sideways by a loop.
struct Straight {
  PlaceMap map{8, 2};
  int32_t segment = -1;
  int slots[4] = {};
};

Straight straight() {
  Straight d;
  d.segment = d.map.createSegment(SE3(Mat3::Identity(), Vec3(0, 10, 0)));
  for (int i = 0; i < 4; ++i) {
    const SE3 T_o_k(Mat3::Identity(), Vec3(2.0 * i, 0, 0));
    d.slots[i] =
        d.map.createKeyframe(d.segment, i, 100 + static_cast<uint64_t>(i), d.map.toWorld(d.segment, T_o_k), T_o_k);
    d.map.addPoint(d.slots[i], pointAt(1, i));
    d.map.finishKeyframe(d.slots[i]);
  }
  d.map.setKeyframePose(d.slots[2], SE3(Mat3::Identity(), Vec3(4, 10.5, 0)));
  return d;
}

// A two-camera rig's centres: camera 1 sits 0.3 m to the side of the body and 0.1 m ahead.
const std::vector<Vec3> kTwoCameraCentres{Vec3::Zero(), Vec3(0.3, 0, 0.1)};

// A point camera 1 of that rig saw, 1.9 m ahead of it.
PlacePoint sidePoint(int32_t node, int64_t landmark) {
  PlacePoint p = pointAt(node, landmark);
  p.cam = 1;
  p.p_k = Eigen::Vector3f(0.3f, 0.f, 2.f);
  return p;
}

// A keyframe of the straight's segment, made at frame 200, holding `points`.
int keyframeHolding(Straight& d, std::initializer_list<PlacePoint> points) {
  const int slot = d.map.createKeyframe(d.segment, 9, 200, SE3(), SE3());
  for (const PlacePoint& p : points) d.map.addPoint(slot, p);
  d.map.finishKeyframe(slot);
  return slot;
}

TEST(PlaceMap, AnArbitraryUnitIsRescaledEverywhere) {
  Straight d = straight();
  d.map.rescaleSegment(d.segment, 2.0, Vec3(2, 0, 0), /*from_frame=*/0, {});
  EXPECT_TRUE(d.map.keyframe(d.slots[0]).T_o_k.t.isApprox(Vec3(-2, 0, 0)));
  EXPECT_TRUE(d.map.keyframe(d.slots[0]).T_w_k.t.isApprox(Vec3(-2, 10, 0)));
  EXPECT_TRUE(d.map.keyframe(d.slots[3]).T_w_k.t.isApprox(Vec3(10, 10, 0)));
  EXPECT_TRUE(d.map.keyframe(d.slots[2]).T_w_k.t.isApprox(Vec3(6, 11, 0)));  // its bend scales with it
  EXPECT_FLOAT_EQ(d.map.points(d.slots[0])[0].p_k.z(), 2.0f);
}

// A unit scales a point's depth from the camera that saw it: its lever arm (metric) stays, so the point stays on
// that camera's ray, and a loop measured on it later is not off by (s - 1) times the lever arm. A point whose
// camera is not among the centres scales about the body.
TEST(PlaceMap, APointScalesAlongTheRayOfTheCameraThatSawIt) {
  Straight d = straight();
  PlaceMap& map = d.map;
  PlacePoint unknown = pointAt(2, 91);
  unknown.cam = 5;
  const int slot = keyframeHolding(d, {sidePoint(1, 90), unknown});
  const std::vector<Vec3>& centers = kTwoCameraCentres;
  map.rescaleSegment(d.segment, 2.0, Vec3(2, 0, 0), /*from_frame=*/0, centers);
  const auto p = map.points(slot);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_TRUE(p[0].p_k.isApprox(Eigen::Vector3f(0.3f, 0.f, 3.9f)));  // 0.1 + 2 (2 - 0.1)
  EXPECT_TRUE(p[1].p_k.isApprox(Eigen::Vector3f(4.f, 0.f, 2.f)));
  map.scaleKeyframe(slot, 0.5, centers);  // a Sim(3) loop's scale, the same way
  EXPECT_TRUE(map.points(slot)[0].p_k.isApprox(Eigen::Vector3f(0.3f, 0.f, 2.f)));
}

// A loop measured camera 1's points of a place in another unit: they take it along their rays, camera 0's stay,
// and the place remembers which were measured until it takes its points anew.
TEST(PlaceMap, AMeasuredUnitScalesOneCamerasPointsAndIsRemembered) {
  Straight d = straight();
  PlaceMap& map = d.map;
  PlacePoint front = pointAt(1, 90);
  front.cam = 0;
  const int slot = keyframeHolding(d, {front, sidePoint(2, 91)});
  map.takeMeasuredUnit(slot, 1, 0.5, kTwoCameraCentres);
  EXPECT_TRUE(map.points(slot)[0].p_k.isApprox(Eigen::Vector3f(1.f, 0.f, 1.f)));     // camera 0's: as it was
  EXPECT_TRUE(map.points(slot)[1].p_k.isApprox(Eigen::Vector3f(0.3f, 0.f, 1.05f)));  // 0.1 + 0.5 (2 - 0.1)
  EXPECT_EQ(map.keyframe(slot).cameras_unit_measured, uint64_t{2});
  map.clearPoints(slot);
  EXPECT_EQ(map.points(slot).size(), 0u);
  EXPECT_EQ(map.keyframe(slot).cameras_unit_measured, uint64_t{0});
}

// The odometry refined a keyframe's pose after the place was made: the world pose takes the same change in the
// keyframe's frame (its translation in the keyframe's unit, here 2 world units per odometry unit), on top of where
// a loop correction had put it; a correction being solved from the pose before is stale.
TEST(PlaceMap, ARefinedPoseKeepsWhatALoopMovedTheKeyframeBy) {
  PlaceMap map(4, 4);
  const int32_t segment = map.createSegment(SE3());
  map.setSegmentScale(segment, 2.0);
  const int slot = map.createKeyframe(segment, 0, 100, SE3(), SE3());
  const SE3 corrected(so3Exp(Vec3(0, 0, M_PI / 2)), Vec3(5, 5, 0));
  map.setKeyframePose(slot, corrected);
  const SE3 change(so3Exp(Vec3(0, 0.1, 0)), Vec3(0.2, 0, 0));
  const uint64_t reshapes = map.reshapes();
  map.refinePose(slot, change);
  EXPECT_TRUE(map.keyframe(slot).T_o_k.t.isApprox(change.t));
  EXPECT_TRUE(map.keyframe(slot).T_w_k.t.isApprox(Vec3(5, 5.4, 0)));  // R_z(90) (0.4, 0, 0)
  EXPECT_TRUE(map.keyframe(slot).T_w_k.R.isApprox(corrected.R * change.R));
  EXPECT_GT(map.reshapes(), reshapes);
}

TEST(PlaceMap, ADriftedUnitIsRescaledFromTheEstimatesWindowOn) {
  Straight d = straight();
  const uint64_t reshapes = d.map.reshapes();
  d.map.rescaleSegment(d.segment, 2.0, Vec3(2, 0, 0), /*from_frame=*/101, {});
  // Made before the window: as they were, so that the motion between them keeps its length.
  EXPECT_TRUE(d.map.keyframe(d.slots[0]).T_o_k.t.isApprox(Vec3(0, 0, 0)));
  EXPECT_TRUE(d.map.keyframe(d.slots[0]).T_w_k.t.isApprox(Vec3(0, 10, 0)));
  EXPECT_FLOAT_EQ(d.map.points(d.slots[0])[0].p_k.z(), 1.0f);
  // From the window's oldest keyframe (the center) on: rescaled about it, in either frame, the loop's bend kept.
  EXPECT_TRUE(d.map.keyframe(d.slots[1]).T_w_k.t.isApprox(Vec3(2, 10, 0)));
  EXPECT_TRUE(d.map.keyframe(d.slots[2]).T_o_k.t.isApprox(Vec3(6, 0, 0)));
  EXPECT_TRUE(d.map.keyframe(d.slots[2]).T_w_k.t.isApprox(Vec3(6, 11, 0)));
  EXPECT_TRUE(d.map.keyframe(d.slots[3]).T_w_k.t.isApprox(Vec3(10, 10, 0)));
  EXPECT_FLOAT_EQ(d.map.points(d.slots[3])[0].p_k.z(), 2.0f);
  EXPECT_GT(d.map.reshapes(), reshapes);  // a correction solved from the poses before is stale
}

}  // namespace
}  // namespace mcslam
