// The JPEG the page codecs are measured against: libjpeg-turbo abbreviated streams, one
// tables-only stream shared by every page (standard Huffman tables) and one stream per page,
// the strongest JPEG a page store can use. Pages are RGB, size x size texels, interleaved.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "common/status.h"

namespace vt::bench {

struct JpegAnchorSettings {
  int page_size = 128;
  int quality = 75;       // libjpeg's 1..100
  bool subsample = true;  // 4:2:0 chroma; false: 4:4:4
};

// Encodes pages one at a time with one set of tables. Not thread-safe.
class JpegPageEncoder {
 public:
  static Expected<JpegPageEncoder> create(const JpegAnchorSettings& settings);
  JpegPageEncoder(JpegPageEncoder&&) noexcept;
  JpegPageEncoder& operator=(JpegPageEncoder&&) noexcept;
  ~JpegPageEncoder();

  const std::vector<uint8_t>& tables() const;  // the shared tables-only stream
  // Replaces `out` with the page's abbreviated stream (no tables in it).
  Status encode(const uint8_t* rgb, std::vector<uint8_t>& out);

 private:
  struct State;
  explicit JpegPageEncoder(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// Decodes abbreviated page streams against the tables an encoder wrote. Not thread-safe.
class JpegPageDecoder {
 public:
  static Expected<JpegPageDecoder> create(int page_size, std::span<const uint8_t> tables);
  JpegPageDecoder(JpegPageDecoder&&) noexcept;
  JpegPageDecoder& operator=(JpegPageDecoder&&) noexcept;
  ~JpegPageDecoder();

  // Writes page_size * page_size * 3 bytes to `rgb`.
  Status decode(std::span<const uint8_t> page, uint8_t* rgb);

 private:
  struct State;
  explicit JpegPageDecoder(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace vt::bench
