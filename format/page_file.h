// The page file (.vtpf): layer descriptions, the streaming writer and the runtime reader.
// docs/FORMAT.md specifies the bytes; this header is the C++ API (format/page_file_c.h is C).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"
#include "format/byte_source.h"
#include "format/page_geometry.h"
#include "format/runtime_format.h"

namespace vt {

enum class LayerSemantic : uint8_t {
  kAlbedo = 0,
  kNormal = 1,
  kOrm = 2,
  kEmissive = 3,
  kCustom = 4,
  kLighting = 5,   // baked irradiance (HDR): added after custom, so earlier files read the same
  kLitAlbedo = 6,  // base colour x irradiance / pi (HDR): `--lighting combined`, likewise added
};

// Storage type of one texel channel.
enum class TexelType : uint8_t { kU8 = 0, kF16 = 1, kF32 = 2 };

// How a stored page's bytes are coded on disk.
enum class PageCodec : uint8_t {
  kRaw = 0,      // page_size^2 texels, channels interleaved, row-major, no compression
  kRawZstd = 1,  // kRaw bytes compressed with zstd (lossless; validation and HDR)
  kDct = 2,      // codec/dct.h page stream, decoded with the layer's shared tables
  kBcZstd = 3,   // the layer's runtime BC format blocks for the whole page, zstd-compressed
};

enum class ColorSpace : uint8_t { kLinear = 0, kSrgb = 1 };

const char* to_string(LayerSemantic v);
// Colour layers (albedo, emissive, lit albedo): linear colour, filtered in linear light, sRGB
// when stored in 8 bits; their 4th channel is alpha.
bool is_colour(LayerSemantic v);
// Light layers (irradiance, lit albedo): unbounded HDR radiometry, half float unless asked for
// 32-bit, judged after a tone map.
bool is_light(LayerSemantic v);
const char* to_string(TexelType v);
const char* to_string(PageCodec v);
const char* to_string(ColorSpace v);
const char* to_string(AddressMode v);
uint32_t texel_type_bytes(TexelType type);

struct LayerSpec {
  LayerSemantic semantic = LayerSemantic::kAlbedo;
  std::string name;      // e.g. "albedo"; unique in the file, at most 255 bytes
  uint8_t channels = 4;  // 1..4
  TexelType texel_type = TexelType::kU8;
  PageCodec codec = PageCodec::kRawZstd;  // the codec of this layer's stored pages
  RuntimeFormat runtime_format = RuntimeFormat::kRgba8;
  ColorSpace color_space = ColorSpace::kLinear;
  AddressMode address_mode = AddressMode::kClamp;
  // Shared codec tables for every page of the layer (codec/dct.h tables for kDct), stored once.
  std::vector<uint8_t> codec_tables;

  uint32_t texel_bytes() const { return channels * texel_type_bytes(texel_type); }
  friend bool operator==(const LayerSpec&, const LayerSpec&) = default;
};

struct PageFileDesc {
  PageGeometry geometry;
  std::vector<LayerSpec> layers;     // 1..16 layers sharing the page grid
  bool align_pages_4k = false;       // start every stored page on a 4 KiB boundary (direct I/O)
  std::string metadata_json = "{}";  // tool version, settings, source hashes
};

// Where a page of a layer stands in the index.
enum class PageState : uint8_t { kAbsent = 0, kConstant = 1, kStored = 2 };

struct PageEntry {
  PageState state = PageState::kAbsent;
  PageCodec codec = PageCodec::kRaw;
  uint64_t offset = 0;    // stored pages: byte offset of the data in the file
  uint32_t size = 0;      // stored pages: byte count of the data
  uint64_t checksum = 0;  // XXH3-64 of the stored bytes (stored) or of the constant value
  // Constant pages: the one texel value every texel of the page has (texel_bytes() bytes).
  uint8_t constant[16] = {};
};

class LayerCodec;  // format/layer_codec.h

// Streams pages into a new page file. Pages may arrive in any order, from any number of
// threads; pages not given are absent. The file appears under `path` only when finish()
// succeeds (written to a temporary name beside it, fsync'ed, renamed); a writer destroyed
// without finish() removes its temporary files and leaves any existing `path` untouched.
// Memory stays bounded: page data goes to a spill file as it arrives and is copied into its
// final place (coarse levels first, Morton order inside a level) by finish(), so the output
// bytes do not depend on arrival order or thread count.
class PageFileWriter {
 public:
  static Expected<std::unique_ptr<PageFileWriter>> create(const std::string& path,
                                                          const PageFileDesc& desc);
  virtual ~PageFileWriter() = default;

  // Adds a stored page: `data` are the bytes coded with the layer's codec. Thread-safe.
  virtual Status add_page(const PageId& id, uint32_t layer, std::span<const uint8_t> data) = 0;
  // Adds a page whose every texel equals `texel` (texel_bytes() bytes). Thread-safe.
  virtual Status add_constant_page(const PageId& id, uint32_t layer,
                                   std::span<const uint8_t> texel) = 0;
  // Replaces the metadata given at create(), before finish(): a build's page keys are known only
  // once its pages are.
  virtual void set_metadata_json(std::string json) = 0;
  // Writes the index and header, fsyncs and renames into place. No add_* after it.
  virtual Status finish() = 0;
};

struct ReaderOptions {
  bool verify_checksums = true;  // verify every page's bytes before returning them
};

// Reads a page file. Never trusts a size or offset from the file: every malformed file gives a
// kCorrupt/kUnsupported Status naming the file and the problem, never a crash, a hang or an
// allocation beyond what the file's own size justifies. Thread-safe for concurrent reads.
// The header and index are read into memory at open; page bytes are read with pread into memory
// the reader owns (never a mapping), so a file truncated or rewritten in place while open gives
// an error on the next read (kCorrupt "file changed while open", or a checksum mismatch when
// ReaderOptions verify), never SIGBUS. Writers replace files by rename, which open readers do
// not see. `path` must be a regular file: a FIFO, device or directory gives kInvalidArgument
// without blocking.
class PageFileReader {
 public:
  static Expected<std::unique_ptr<PageFileReader>> open(const std::string& path,
                                                        const ReaderOptions& options = {});
  // The same over the engine's own storage; `name` stands for the path in path() and messages.
  static Expected<std::unique_ptr<PageFileReader>> open(std::shared_ptr<const ByteSource> bytes,
                                                        const std::string& name,
                                                        const ReaderOptions& options = {});
  virtual ~PageFileReader() = default;

  virtual const std::string& path() const = 0;
  virtual const PageGeometry& geometry() const = 0;
  virtual const std::vector<LayerSpec>& layers() const = 0;
  virtual const std::string& metadata_json() const = 0;
  virtual uint32_t version() const = 0;
  virtual uint64_t file_size() const = 0;

  // The index entry of a page (id must satisfy geometry().contains(id), layer < layers()).
  virtual Expected<PageEntry> entry(const PageId& id, uint32_t layer) const = 0;
  // The stored bytes of a kStored page, checksum-verified if the options ask for it.
  virtual Expected<std::vector<uint8_t>> read_stored(const PageId& id, uint32_t layer) const = 0;
  // Decoded texels of a stored or constant page: page_size^2 texels of layer.texel_bytes()
  // each, channels interleaved, row-major (BC pages are decoded and keep the layer's channels).
  // `out` must hold decoded_page_bytes(layer). Absent pages give kNotFound.
  virtual Status read_texels(const PageId& id, uint32_t layer, std::span<uint8_t> out) const = 0;
  // Bytes read_texels writes for this layer.
  virtual size_t decoded_page_bytes(uint32_t layer) const = 0;
  // The codec read_texels decodes the layer's pages with (layer < layers()), made when the file
  // opened: for callers that want a stored page's BC blocks as they are (runtime/page_source).
  virtual const LayerCodec& layer_codec(uint32_t layer) const = 0;
  // Checks a page's stored bytes against the index checksum whatever ReaderOptions say (Ok for
  // constant and absent pages: open() checked their index entries).
  virtual Status verify_page(const PageId& id, uint32_t layer) const = 0;
  // Checks every stored page's checksum (open() has checked the header and the index): the first
  // bad page's error. verify_pages (format/page_file_inspect.h) lists every bad page, threaded.
  Status verify() const;
};

}  // namespace vt
