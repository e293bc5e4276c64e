#include "mcslam/places/map_contents.hpp"

#include <algorithm>

namespace mcslam {

MapContents readMapContents(std::string_view bytes, const std::string& name) {
  MapContents c;
  c.file_bytes = bytes.size();
  ByteReader in({}, name);
  c.header = openMapFile(bytes, name, in);
  const MapFileHeader& h = c.header;
  const MapFileFields fields = MapFileFields::ofVersion(h.version);
  // The header's counts size the memory: each must fit the bytes that follow, at what it takes on disk at least,
  // so that a forged header cannot ask for much more memory than the file's size. Point slots are kept per
  // keyframe (keyframes x the fullest one's points): a map of sparse keyframes needs more slots than points, so
  // that product is bounded by the file's bytes (about 70 per point) or 4 M slots, whichever is more.
  const uint64_t remaining = in.remaining();
  const uint64_t slots = uint64_t{h.keyframes} * h.max_points_per_keyframe;
  const bool counts_fit = h.keyframes <= remaining / PlaceMap::keyframeFileBytes(fields) &&
                          h.max_points_per_keyframe <= h.points && h.points <= remaining / PlaceMap::pointFileBytes() &&
                          slots <= std::max<uint64_t>(remaining, 1u << 22) &&
                          h.loops <= remaining / loopFileBytes(fields.scales);
  if (!counts_fit) in.fail("the header counts more keyframes, points or loops than the file can hold");
  c.map = std::make_unique<PlaceMap>(static_cast<int>(h.keyframes), static_cast<int>(h.max_points_per_keyframe));
  c.map->read(in, static_cast<int>(h.cameras.size()), fields);
  BowVector words(static_cast<int>(std::min<uint64_t>(h.vocabulary_words, in.remaining() / kWordFileBytes)));
  for (int slot = 0; slot < c.map->size(); ++slot) {
    takeKeyframeWords(in, static_cast<int>(h.vocabulary_words), c.map->keyframe(slot).id, "the vocabulary's words",
                      words);
    c.words.push_back(static_cast<uint32_t>(words.size()));
  }
  c.loops.resize(h.loops);
  c.segment_roots.resize(static_cast<std::size_t>(c.map->segments()));
  c.loops.resize(static_cast<std::size_t>(takeLoops(in, c.map->segments(), c.loops, c.segment_roots, fields.scales)));
  if (in.remaining() != 0) in.fail(std::to_string(in.remaining()) + " bytes of trailing data");
  return c;
}

}  // namespace mcslam
