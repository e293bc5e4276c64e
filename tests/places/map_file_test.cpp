// The map file: the place map survives a write and a read (keyframes, chains, points, ids), whatever the slots;
// a truncated, corrupt, foreign, newer or oversized file, or one of another rig or vocabulary, is refused with an
// error naming the file and the fault; a version 2 file reads as made in a known unit; writing into a buffer sized
// from the capacities allocates nothing.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <memory>

#include "alloc_testing.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/places/map_contents.hpp"
#include "mcslam/places/map_file.hpp"
#include "mcslam/places/place_map.hpp"
#include "mcslam/places/place_memory.hpp"
#include "test_support.hpp"

namespace mcslam {
namespace {

PlacePoint pointAt(int32_t node, int64_t landmark, int16_t cam) {
  PlacePoint p;
  p.node = node;
  p.landmark_id = landmark;
  p.cam = cam;
  p.octave = static_cast<int8_t>(node % 4);
  p.p_k = Eigen::Vector3f(static_cast<float>(node), 0.5f, 2.0f);
  p.descriptor.fill(static_cast<uint8_t>(landmark));
  return p;
}

SE3 poseAt(double x, double yaw) {
  return SE3(Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix(), Vec3(x, 1, 0));
}

// Two segments, a recycled slot in the middle: slots are not the file's order.
PlaceMap sampleMap() {
  PlaceMap map(8, 5);
  const int32_t s0 = map.createSegment(SE3());
  const int32_t s1 = map.createSegment(poseAt(3, 0.2), /*placed=*/false);
  map.setSegmentScale(s1, 0.8);  // a Sim(3) loop corrected its unit
  for (int i = 0; i < 5; ++i) {
    const int k = map.createKeyframe(i % 2 ? s1 : s0, 100 + i, 10 + static_cast<uint64_t>(i), poseAt(i, 0.1 * i),
                                     poseAt(i, 0.1 * i + 0.05));
    for (int j = 0; j < i; ++j) map.addPoint(k, pointAt(10 * i + j, 100 * i + j, static_cast<int16_t>(j % 2)));
    map.finishKeyframe(k);
    map.setUnitSigma(k, 0.1 * i);  // made while a rig without overlap was finding its unit
  }
  map.scaleKeyframe(3, 1.25, {});
  map.eraseKeyframe(2);
  return map;
}

std::string written(const PlaceMap& map) {
  std::string bytes;
  ByteWriter w(bytes);
  map.write(w);
  return bytes;
}

// The place map's part of a version 2 file: version 3's with each keyframe's unit sigma (the last double before
// its links and point count) taken out.
std::string asVersion2(const std::string& v3, const PlaceMap& map) {
  const std::size_t record = PlaceMap::keyframeFileBytes();
  const std::size_t pose = (record - 56) / 2;  // the record's two poses; the rest is 56 bytes of ids and numbers
  const std::size_t sigma_at = record - 12 - sizeof(double);
  std::size_t at = sizeof(int64_t) + sizeof(uint32_t) + static_cast<std::size_t>(map.segments()) * (pose + 9);
  std::string v2 = v3.substr(0, at + sizeof(uint32_t));
  uint32_t keyframes = 0;
  std::memcpy(&keyframes, v3.data() + at, sizeof(keyframes));
  at += sizeof(uint32_t);
  for (uint32_t k = 0; k < keyframes; ++k) {
    uint32_t points = 0;
    std::memcpy(&points, v3.data() + at + record - sizeof(uint32_t), sizeof(points));
    v2 += v3.substr(at, sigma_at);
    v2 += v3.substr(at + sigma_at + sizeof(double), 12 + points * PlaceMap::pointFileBytes());
    at += record + points * PlaceMap::pointFileBytes();
  }
  EXPECT_EQ(at, v3.size());
  return v2;
}

TEST(MapFile, AVersion2MapReadsAsMadeInAKnownUnit) {
  const PlaceMap before = sampleMap();
  const std::string v2 = asVersion2(written(before), before);
  ASSERT_EQ(v2.size() + static_cast<std::size_t>(before.size()) * sizeof(double), written(before).size());
  PlaceMap after(6, 5);
  ByteReader in(v2, "old.map");
  after.read(in, 2, MapFileFields::ofVersion(2));
  EXPECT_EQ(in.remaining(), 0u);
  ASSERT_EQ(after.size(), before.size());
  int slot = 0;
  for (int b = 0; b < before.capacity(); ++b) {
    const PlaceKeyframe& k = before.keyframe(b);
    if (!k.alive) continue;
    const PlaceKeyframe& r = after.keyframe(slot++);
    EXPECT_EQ(r.id, k.id);
    EXPECT_EQ(r.unit, k.unit);
    EXPECT_EQ(r.unit_sigma, 0.0);
    EXPECT_EQ(r.point_count, k.point_count);
  }
  // Read as version 3 it is refused, not misread.
  PlaceMap misread(6, 5);
  ByteReader as_v3(v2, "old.map");
  EXPECT_THROW(misread.read(as_v3, 2), InputError);
}

TEST(MapFile, ThePlaceMapSurvivesAWriteAndARead) {
  const PlaceMap before = sampleMap();
  const std::string bytes = written(before);
  PlaceMap after(6, 5);
  ByteReader in(bytes, "sample.map");
  after.read(in, 2);
  EXPECT_EQ(in.remaining(), 0u);
  ASSERT_EQ(after.size(), before.size());
  EXPECT_EQ(after.nextId(), before.nextId());
  ASSERT_EQ(after.segments(), 2);
  EXPECT_TRUE(after.placed(0));
  EXPECT_FALSE(after.placed(1));
  EXPECT_TRUE(after.segmentPose(1).t.isApprox(before.segmentPose(1).t));
  EXPECT_EQ(after.segmentScale(0), 1.0);
  EXPECT_EQ(after.segmentScale(1), 0.8);
  EXPECT_EQ(after.keyframe(after.newestKeyframe()).id, before.keyframe(before.newestKeyframe()).id);
  int slot = 0;
  for (int b = 0; b < before.capacity(); ++b) {
    const PlaceKeyframe& k = before.keyframe(b);
    if (!k.alive) continue;
    const PlaceKeyframe& r = after.keyframe(slot);
    EXPECT_EQ(r.id, k.id);
    EXPECT_EQ(r.segment, k.segment);
    EXPECT_EQ(r.t, k.t);
    EXPECT_EQ(r.frame_index, k.frame_index);
    EXPECT_TRUE(r.T_w_k.R.isApprox(k.T_w_k.R) && r.T_w_k.t.isApprox(k.T_w_k.t));
    EXPECT_TRUE(r.T_o_k.t.isApprox(k.T_o_k.t));
    EXPECT_EQ(r.unit, k.unit);
    EXPECT_EQ(r.unit_sigma, k.unit_sigma);
    // Neighbours are the same keyframes (by id), in other slots.
    EXPECT_EQ(r.previous < 0 ? -1 : after.keyframe(r.previous).id,
              k.previous < 0 ? -1 : before.keyframe(k.previous).id);
    EXPECT_EQ(r.next < 0 ? -1 : after.keyframe(r.next).id, k.next < 0 ? -1 : before.keyframe(k.next).id);
    ASSERT_EQ(after.points(slot).size(), before.points(b).size());
    for (std::size_t i = 0; i < before.points(b).size(); ++i) {
      const PlacePoint &p = before.points(b)[i], &q = after.points(slot)[i];
      EXPECT_EQ(q.node, p.node);
      EXPECT_EQ(q.cam, p.cam);
      EXPECT_EQ(q.octave, p.octave);
      EXPECT_EQ(q.landmark_id, p.landmark_id);
      EXPECT_EQ(q.descriptor, p.descriptor);
      EXPECT_TRUE(q.p_k.isApprox(p.p_k));
    }
    ++slot;
  }
  // The loaded map goes on: a new keyframe takes the next free slot and a new id.
  const int k = after.createKeyframe(0, 0, 0, SE3(), SE3());
  EXPECT_EQ(k, after.size() - 1);
  EXPECT_EQ(after.keyframe(k).id, before.nextId());
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(MapFile, AMapLargerThanTheCapacitiesIsRefusedNamingTheSetting) {
  const std::string bytes = written(sampleMap());
  PlaceMap few_keyframes(3, 5), few_points(8, 2);
  EXPECT_NE(errorOf([&] {
              ByteReader in(bytes, "big.map");
              few_keyframes.read(in, 2);
            }).find("big.map: 4 keyframes, more than places.max_keyframes (3)"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              ByteReader in(bytes, "big.map");
              few_points.read(in, 2);
            }).find("more than places.max_points_per_keyframe (2)"),
            std::string::npos);
  PlaceMap one_camera(8, 5);
  EXPECT_NE(errorOf([&] {
              ByteReader in(bytes, "big.map");
              one_camera.read(in, 1);
            }).find("a point of camera 1"),
            std::string::npos);
}

TEST(MapFile, EveryTruncationOfTheMapPartIsAnErrorNotACrash) {
  const std::string bytes = written(sampleMap());
  for (std::size_t n = 0; n < bytes.size(); n += 7) {
    PlaceMap map(8, 5);
    ByteReader in(std::string_view(bytes).substr(0, n), "cut.map");
    EXPECT_NE(errorOf([&] { map.read(in, 2); }).find("cut.map: "), std::string::npos) << n;
  }
}

std::string sampleFile() {
  MapFileHeader h;
  h.cameras = {{640, 480}, {640, 480}};
  h.keyframes = 4;
  std::string out;
  beginMapFile(out, h);
  out += written(sampleMap());
  finishMapFile(out);
  return out;
}

std::string openError(const std::string& bytes) {
  return errorOf([&] {
    ByteReader payload({}, "robot.map");
    openMapFile(bytes, "robot.map", payload);
  });
}

TEST(MapFile, TheEnvelopeRefusesForeignTruncatedCorruptAndNewerFiles) {
  const std::string good = sampleFile();
  ByteReader payload({}, "robot.map");
  const MapFileHeader h = openMapFile(good, "robot.map", payload);
  EXPECT_EQ(h.cameras.size(), 2u);
  EXPECT_EQ(h.cameras[1].width, 640u);
  EXPECT_EQ(h.keyframes, 4u);
  EXPECT_EQ(openError("P5\n640 480\n255\n"), "robot.map: not an mcslam map file (it does not start with 'MCSLMAP')");
  EXPECT_NE(openError(good.substr(0, good.size() - 10)).find("(truncated)"), std::string::npos);
  EXPECT_NE(openError(good + "x").find("(trailing data)"), std::string::npos);
  std::string corrupt = good;
  corrupt[corrupt.size() / 2] ^= 0x10;
  EXPECT_EQ(openError(corrupt), "robot.map: checksum mismatch: the map file is corrupt");
  std::string newer = good;
  newer[8] = 9;
  EXPECT_EQ(openError(newer), "robot.map: map file version 9, this build reads versions 1 to 3");
}

Rig isecRig(const std::vector<int>& cameras) {
  return loadKalibrRig(test::dataPath("calib/isec_5cam_camchain.yaml")).subset(cameras);
}

const Vocabulary& shippedVocabulary() {
  static const Vocabulary v = loadVocabulary("");
  return v;
}

std::unique_ptr<PlaceMemory> memoryFor(const Rig& rig, const Vocabulary& vocabulary) {
  PlacesOptions places;
  places.max_keyframes = 8;
  places.max_points_per_keyframe = 5;
  places.max_words_per_keyframe = 3;
  return std::make_unique<PlaceMemory>(rig, vocabulary, places, OdometryOptions{}, 100);
}

// A whole map file as PlaceMemory writes it: the sample map, each keyframe's words, no loop.
std::string memoryFile(const Rig& rig) {
  const PlaceMap map = sampleMap();
  MapFileHeader h;
  for (int c = 0; c < rig.size(); ++c)
    h.cameras.push_back({static_cast<uint32_t>(rig.model(c).width()), static_cast<uint32_t>(rig.model(c).height())});
  h.vocabulary_words = static_cast<uint32_t>(shippedVocabulary().wordCount());
  h.vocabulary_fingerprint = vocabularyFingerprint(shippedVocabulary());
  for (int slot = 0; slot < map.capacity(); ++slot) {
    if (!map.keyframe(slot).alive) continue;
    ++h.keyframes;
    h.points += map.points(slot).size();
    h.max_points_per_keyframe = std::max<uint32_t>(h.max_points_per_keyframe, map.points(slot).size());
  }
  h.segments = 2;
  std::string out;
  beginMapFile(out, h);
  ByteWriter w(out);
  map.write(w);
  for (uint32_t k = 0; k < h.keyframes; ++k) {
    w.put<uint32_t>(2);
    for (int32_t word : {static_cast<int32_t>(k), static_cast<int32_t>(100 + k)}) {
      w.put<int32_t>(word);
      w.put<float>(0.5f);
    }
  }
  w.put<uint32_t>(0);                                // loops
  for (int32_t root : {0, 1}) w.put<int32_t>(root);  // segments joined by none
  finishMapFile(out);
  return out;
}

TEST(MapFile, APlaceMemoryReadsAMapAndWritesTheSameBytesWithoutAllocating) {
  const Rig rig = isecRig({0, 1});
  const std::string file = memoryFile(rig);
  auto memory = memoryFor(rig, shippedVocabulary());
  memory->readMap(file, "robot.map");
  EXPECT_TRUE(memory->mapLoaded());
  EXPECT_EQ(memory->map().size(), 4);
  std::string again;
  again.reserve(memory->maxMapBytes());
  {
    SKIP_UNLESS_COUNTING_ALLOCATIONS();
    alloc::ThreadScope scope;
    memory->writeMap(again);
    EXPECT_EQ(scope.count(), 0u);
  }
  EXPECT_TRUE(again == file);
}

// Tools read a map whole, sized by the file: the same keyframes, words and joined segments; a cut file is refused.
TEST(MapFile, AToolReadsAWholeMapWithoutCapacities) {
  const std::string file = memoryFile(isecRig({0, 1}));
  const MapContents c = readMapContents(file, "robot.map");
  EXPECT_EQ(c.file_bytes, file.size());
  EXPECT_EQ(c.header.cameras.size(), 2u);
  ASSERT_EQ(c.map->size(), 4);
  EXPECT_EQ(c.map->segments(), 2);
  EXPECT_EQ(c.words, (std::vector<uint32_t>{2, 2, 2, 2}));
  EXPECT_TRUE(c.loops.empty());
  EXPECT_EQ(c.segment_roots, (std::vector<int32_t>{0, 1}));
  for (std::size_t n : {file.size() - 1, file.size() / 2, std::size_t{20}}) {
    std::string cut = file.substr(0, n);
    EXPECT_NE(errorOf([&] { readMapContents(cut, "cut.map"); }).find("cut.map: "), std::string::npos) << n;
  }
}

TEST(MapFile, AMapOfAnotherRigOrVocabularyIsRefused) {
  const std::string file = memoryFile(isecRig({0, 1}));
  auto three = memoryFor(isecRig({0, 1, 2}), shippedVocabulary());
  EXPECT_NE(errorOf([&] { three->readMap(file, "robot.map"); })
                .find("robot.map: the map was made by a rig of 2 cameras (720x540, 720x540), this one has 3 cameras "
                      "(720x540, 720x540, 720x540)"),
            std::string::npos);
  const Vocabulary other(2, 2);
  auto stranger = memoryFor(isecRig({0, 1}), other);
  EXPECT_NE(errorOf([&] {
              stranger->readMap(file, "robot.map");
            }).find("robot.map: the map was made with another vocabulary"),
            std::string::npos);
}

}  // namespace
}  // namespace mcslam
