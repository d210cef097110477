// Internal to vt_scene: what the OBJ and MTL readers share (their text comes through
// decode_text, scene_io_util.h): a line cursor, quoted tokens, and file names as exporters write
// them (backslashes, Windows drive paths, case that differs from the disk).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/status.h"
#include "scene/scene.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {

// Reads one OBJ/MTL statement at a time; `p` is at the start of a line after next_line().
struct LineCursor {
  const char* p;
  const char* end;

  void skip_space();
  bool at_line_end();          // after skipping blanks: end of line, of file, or a comment
  std::string word();          // the next blank-separated token
  std::string rest_of_line();  // trimmed; comments are part of it (names may hold '#')
  bool number(float* out);     // also "+1", "2.", "nan", "inf"; false: nothing read
  void next_line();
};

// A statement's arguments split at blanks, with "double quoted" runs kept whole (quotes
// removed). `begin` is each token's offset in `text`, so a caller can take the unsplit rest.
struct Token {
  std::string text;
  size_t begin = 0;
};
std::vector<Token> split_tokens(const std::string& text);

// One channel of a packed map: channel `channel` of the image at `path` (resampled to the
// largest source's size; -1 = its alpha when it has one, else its first), or `constant` when
// `path` is empty.
struct ChannelSource {
  std::string path;
  int channel = 0;
  float constant = 1.0f;
};

// An embedded PNG whose channels come from other images (8-bit, or 16-bit when a source has
// more bits); values are copied as stored, with no colour conversion. For MTL maps that glTF
// keeps in one texture: map_Kd + map_d as base colour + alpha, map_Pr + map_Pm as G and B of
// the metallic-roughness texture. Errors name the image that could not be read.
Expected<Image> composite_image(const std::vector<ChannelSource>& channels,
                                const std::string& name);

// An MTL library read into `scene->materials` (and the images they use into scene->images);
// `by_name` maps material names to indices. Warnings name the MTL file; an error only when the
// file cannot be read (the OBJ then keeps default materials).
Status load_mtl(const std::string& path, Scene* scene, std::map<std::string, int>* by_name);

}  // namespace vt::scene::detail
