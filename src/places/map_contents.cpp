#include "mcslam/places/map_contents.hpp"

#include <algorithm>

namespace mcslam {

MapContents readMapContents(std::string_view bytes, const std::string& name) {
  MapContents c;
  c.file_bytes = bytes.size();
  ByteReader in({}, name);
  c.header = openMapFile(bytes, name, in);
  const MapFileHeader& h = c.header;
  // The header's counts size the memory; the parts are then checked against them as against capacities.
  if (h.keyframes > static_cast<uint64_t>(in.remaining()) || h.loops > static_cast<uint64_t>(in.remaining()) ||
      uint64_t{h.keyframes} * h.max_points_per_keyframe > in.remaining())
    in.fail("the header counts more keyframes, points or loops than the file can hold");
  c.map = std::make_unique<PlaceMap>(static_cast<int>(h.keyframes), static_cast<int>(h.max_points_per_keyframe));
  c.map->read(in, static_cast<int>(h.cameras.size()));
  BowVector words(static_cast<int>(std::min<uint64_t>(h.vocabulary_words, in.remaining() / 8)));
  for (int slot = 0; slot < c.map->size(); ++slot) {
    takeKeyframeWords(in, static_cast<int>(h.vocabulary_words), c.map->keyframe(slot).id, "the vocabulary's words",
                      words);
    c.words.push_back(static_cast<uint32_t>(words.size()));
  }
  c.loops.resize(h.loops);
  c.segment_roots.resize(static_cast<std::size_t>(c.map->segments()));
  c.loops.resize(static_cast<std::size_t>(takeLoops(in, c.map->segments(), c.loops, c.segment_roots)));
  if (in.remaining() != 0) in.fail(std::to_string(in.remaining()) + " bytes of trailing data");
  return c;
}

}  // namespace mcslam
