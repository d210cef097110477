// The runtime page-file reader: reads the header and index into owned memory, validates every
// count, offset and size against the real file size before using it, then serves pages to any
// number of threads with pread.
#include <xxhash.h>

#include <algorithm>
#include <cstring>

#include "format/layer_codec.h"
#include "format/page_file.h"
#include "format/page_file_layout.h"
#include "format/platform_file.h"

namespace vt {

namespace {

using namespace pagefile;

class PageFileReaderImpl final : public PageFileReader {
 public:
  PageFileReaderImpl(std::string path, ReaderOptions options,
                     std::shared_ptr<const ByteSource> bytes = nullptr)
      : path_(std::move(path)), options_(options), file_(std::move(bytes)) {}

  Status open_and_validate() {
    if (!file_) {
      VT_ASSIGN_OR_RETURN(auto file, platform::ReadOnlyFile::open(path_));
      file_ = std::move(file);
    }
    size_ = file_->size();
    if (size_ < kFixedHeaderBytes)
      return corrupt("truncated: " + std::to_string(size_) + " bytes is less than a header");
    VT_RETURN_IF_ERROR(parse_header());
    VT_RETURN_IF_ERROR(validate_index());
    return Status::Ok();
  }

  const std::string& path() const override { return path_; }
  const PageGeometry& geometry() const override { return geometry_; }
  const std::vector<LayerSpec>& layers() const override { return layers_; }
  const std::string& metadata_json() const override { return metadata_; }
  uint32_t version() const override { return version_; }
  uint64_t file_size() const override { return size_; }

  Expected<PageEntry> entry(const PageId& id, uint32_t layer) const override {
    VT_ASSIGN_OR_RETURN(uint64_t slot, slot_of(id, layer));
    return parse_entry(slot);
  }

  Expected<std::vector<uint8_t>> read_stored(const PageId& id, uint32_t layer) const override {
    std::vector<uint8_t> bytes;
    VT_RETURN_IF_ERROR(stored_bytes(id, layer, bytes));
    return bytes;
  }

  Status read_texels(const PageId& id, uint32_t layer, std::span<uint8_t> out) const override {
    VT_ASSIGN_OR_RETURN(uint64_t slot, slot_of(id, layer));
    if (out.size() != decoded_page_bytes(layer))
      return Error(ErrorCode::kInvalidArgument, path_ + ": " + page_name(id, layer) +
                                                    ": output of " + std::to_string(out.size()) +
                                                    " bytes, expected " +
                                                    std::to_string(decoded_page_bytes(layer)));
    PageEntry e = parse_entry(slot);
    if (e.state == PageState::kAbsent)
      return Error(ErrorCode::kNotFound, path_ + ": " + page_name(id, layer) + " is absent");
    if (e.state == PageState::kConstant) {
      const size_t tb = layers_[layer].texel_bytes();
      for (size_t i = 0; i < out.size(); i += tb) std::memcpy(out.data() + i, e.constant, tb);
      return Status::Ok();
    }
    if (layers_[layer].codec == PageCodec::kRaw) {
      // validate_index() checked that a raw page is exactly out.size() bytes: read in place.
      VT_RETURN_IF_ERROR(read_at(e.offset, out, &id, layer));
      return options_.verify_checksums ? check_stored(id, layer, e, out) : Status::Ok();
    }
    thread_local std::vector<uint8_t> bytes;
    VT_RETURN_IF_ERROR(stored_bytes(id, layer, bytes));
    return codecs_[layer].decode(bytes, out).with_context(path_ + ": " + page_name(id, layer));
  }

  size_t decoded_page_bytes(uint32_t layer) const override {
    if (layer >= layers_.size()) return 0;
    const size_t size = geometry_.page_size();
    return size * size * layers_[layer].texel_bytes();
  }

  const LayerCodec& layer_codec(uint32_t layer) const override { return codecs_[layer]; }

  Status verify_page(const PageId& id, uint32_t layer) const override {
    VT_ASSIGN_OR_RETURN(uint64_t slot, slot_of(id, layer));
    PageEntry e = parse_entry(slot);
    if (e.state != PageState::kStored) return Status::Ok();
    thread_local std::vector<uint8_t> bytes;
    bytes.resize(e.size);
    VT_RETURN_IF_ERROR(read_at(e.offset, bytes, &id, layer));
    return check_stored(id, layer, e, bytes);
  }

 private:
  Status corrupt(const std::string& what) const { return Error(ErrorCode::kCorrupt, what); }

  // Reads exactly out.size() bytes at `offset` into memory this reader owns (positioned reads,
  // never a mapping: a file truncated or rewritten while open gives an error, not SIGBUS).
  Status read_at(uint64_t offset, std::span<uint8_t> out, const PageId* id = nullptr,
                 uint32_t layer = 0) const {
    size_t done = 0;
    while (done < out.size()) {
      Expected<size_t> n = file_->read_some(offset + done, out.subspan(done));
      if (!n.ok() || *n == 0) {
        // Page reads name the file and page; open() adds the path to its own errors.
        const std::string what = id ? path_ + ": " + page_name(*id, layer) + ": " : std::string();
        if (!n.ok()) return Error(n.status().code(), what + n.status().message());
        return corrupt(what + "file changed while open: " + std::to_string(out.size()) +
                       " bytes at offset " + std::to_string(offset) +
                       " end past its end (truncated)");
      }
      done += *n;
    }
    return Status::Ok();
  }

  Expected<uint64_t> slot_of(const PageId& id, uint32_t layer) const {
    if (!geometry_.contains(id) || layer >= layers_.size())
      return Error(ErrorCode::kInvalidArgument,
                   path_ + ": " + page_name(id, layer) + " is outside the file's geometry");
    const uint64_t page =
        level_first_[id.level] + uint64_t(id.y) * geometry_.pages_x(id.level) + id.x;
    return page * layers_.size() + layer;
  }

  // Decodes an index entry that open() has already validated.
  PageEntry parse_entry(uint64_t slot) const {
    const uint8_t* p = index_.data() + slot * kEntryBytes;
    PageEntry e;
    e.state = PageState(p[0]);
    e.codec = PageCodec(p[1]);
    e.size = get_u32(p + 4);
    if (e.state == PageState::kStored) e.offset = get_u64(p + 8);
    if (e.state == PageState::kConstant) std::memcpy(e.constant, p + 8, 16);
    e.checksum = get_u64(p + 24);
    return e;
  }

  Status check_stored(const PageId& id, uint32_t layer, const PageEntry& e,
                      std::span<const uint8_t> bytes) const {
    if (XXH3_64bits(bytes.data(), bytes.size()) != e.checksum)
      return Error(ErrorCode::kCorrupt,
                   path_ + ": " + page_name(id, layer) + ": checksum mismatch in stored bytes");
    return Status::Ok();
  }

  // The stored bytes of a kStored page into `out` (resized), checksum-verified if asked.
  Status stored_bytes(const PageId& id, uint32_t layer, std::vector<uint8_t>& out) const {
    VT_ASSIGN_OR_RETURN(uint64_t slot, slot_of(id, layer));
    PageEntry e = parse_entry(slot);
    if (e.state != PageState::kStored)
      return Error(ErrorCode::kNotFound,
                   path_ + ": " + page_name(id, layer) + " is " +
                       (e.state == PageState::kAbsent ? "absent" : "constant") + ", not stored");
    out.resize(e.size);
    VT_RETURN_IF_ERROR(read_at(e.offset, out, &id, layer));
    return options_.verify_checksums ? check_stored(id, layer, e, out) : Status::Ok();
  }

  Status parse_header();
  Status parse_layers(uint64_t begin, uint64_t end);
  Status validate_index();

  std::string path_;
  ReaderOptions options_;
  std::shared_ptr<const ByteSource> file_;  // a platform file, or the engine's storage
  uint64_t size_ = 0;
  uint32_t version_ = 0;
  std::vector<uint8_t> header_;  // the whole header, checksum included
  std::vector<uint8_t> index_;   // the whole index, read once at open
  PageGeometry geometry_;
  std::vector<LayerSpec> layers_;
  std::vector<LayerCodec> codecs_;
  std::string metadata_;
  std::vector<uint64_t> level_first_;
  bool align_4k_ = false;
  uint64_t index_offset_ = 0, index_size_ = 0, entry_count_ = 0;
  uint64_t data_offset_ = 0, data_size_ = 0;
};

Status PageFileReaderImpl::parse_header() {
  header_.resize(kFixedHeaderBytes);
  VT_RETURN_IF_ERROR(read_at(0, header_));
  if (std::memcmp(header_.data(), kMagic, 8) != 0) return corrupt("not a page file (bad magic)");
  const uint8_t* h = header_.data();
  version_ = get_u32(h + kOffVersion);
  if (version_ == 0) return corrupt("version 0 is not valid");
  if (version_ > kVersion)
    return Error(ErrorCode::kUnsupported, "page file version " + std::to_string(version_) +
                                              " is newer than this reader (version " +
                                              std::to_string(kVersion) + ")");
  const uint64_t header_size = get_u32(h + kOffHeaderSize);
  if (header_size > size_)
    return corrupt("truncated: header of " + std::to_string(header_size) + " bytes, file of " +
                   std::to_string(size_));
  if (header_size < kFixedHeaderBytes + 8 || header_size % 8 != 0)
    return corrupt("header size " + std::to_string(header_size) + " is invalid");
  header_.resize(size_t(header_size));  // at most the file's size, checked above
  VT_RETURN_IF_ERROR(read_at(0, header_));
  h = header_.data();
  if (XXH3_64bits(h, size_t(header_size - 8)) != get_u64(h + header_size - 8))
    return corrupt("header checksum mismatch");
  if (get_u32(h + kOffFlags) & ~kFlagAlign4k)
    return Error(ErrorCode::kUnsupported, "unknown header flags");
  if (get_u32(h + kOffReserved) != 0) return corrupt("reserved header field is not zero");
  align_4k_ = (get_u32(h + kOffFlags) & kFlagAlign4k) != 0;

  geometry_.width = get_u32(h + kOffWidth);
  geometry_.height = get_u32(h + kOffHeight);
  geometry_.payload = get_u32(h + kOffPayload);
  geometry_.border = get_u32(h + kOffBorder);
  Status g = geometry_.validate();
  if (!g.ok()) return corrupt(g.message());
  const uint32_t levels = get_u32(h + kOffLevelCount);
  if (levels != geometry_.level_count())
    return corrupt("level count " + std::to_string(levels) + " does not match the geometry (" +
                   std::to_string(geometry_.level_count()) + ")");
  const uint32_t layer_count = get_u32(h + kOffLayerCount);
  if (layer_count < 1 || layer_count > kMaxLayers)
    return corrupt("layer count " + std::to_string(layer_count) + " is not 1..16");
  const uint64_t grid_end = kFixedHeaderBytes + uint64_t(levels) * kLevelRecordBytes;
  if (grid_end > header_size - 8) return corrupt("level grid table overruns the header");
  for (uint32_t l = 0; l < levels; ++l) {
    const uint8_t* p = h + kFixedHeaderBytes + l * kLevelRecordBytes;
    if (get_u32(p) != geometry_.pages_x(l) || get_u32(p + 4) != geometry_.pages_y(l))
      return corrupt("level " + std::to_string(l) + " page grid does not match the geometry");
  }
  layers_.resize(layer_count);
  VT_RETURN_IF_ERROR(parse_layers(grid_end, header_size - 8));

  level_first_.resize(levels);
  for (uint32_t l = 0; l < levels; ++l) level_first_[l] = level_first_page(geometry_, l);
  entry_count_ = geometry_.total_pages() * layer_count;  // < 2^34: no overflow below

  index_offset_ = get_u64(h + kOffIndexOffset);
  index_size_ = get_u64(h + kOffIndexSize);
  data_offset_ = get_u64(h + kOffDataOffset);
  data_size_ = get_u64(h + kOffDataSize);
  const uint64_t meta_offset = get_u64(h + kOffMetadataOffset);
  const uint64_t meta_size = get_u64(h + kOffMetadataSize);
  const uint64_t file_size = get_u64(h + kOffFileSize);
  if (file_size != size_)
    return corrupt("truncated or extended: header says " + std::to_string(file_size) +
                   " bytes, file has " + std::to_string(size_));
  if (index_offset_ != header_size) return corrupt("index does not follow the header");
  if (index_size_ != entry_count_ * kEntryBytes)
    return corrupt("index size " + std::to_string(index_size_) + " does not match " +
                   std::to_string(entry_count_) + " entries");
  if (index_size_ > size_ - index_offset_) return corrupt("index extends past the end of the file");
  if (data_offset_ != align_up(index_offset_ + index_size_, align_4k_ ? kPageAlignment : 8))
    return corrupt("data area does not follow the index");
  if (data_offset_ > size_ || data_size_ > size_ - data_offset_)
    return corrupt("data area extends past the end of the file");
  if (meta_offset != data_offset_ + data_size_)
    return corrupt("metadata does not follow the data area");
  if (meta_size != size_ - meta_offset) return corrupt("metadata does not end the file");
  // Both sizes lie inside the file (checked above), so these buffers are backed by its bytes.
  index_.resize(size_t(index_size_));
  VT_RETURN_IF_ERROR(read_at(index_offset_, index_));
  if (XXH3_64bits(index_.data(), index_.size()) != get_u64(h + kOffIndexChecksum))
    return corrupt("index checksum mismatch");
  std::vector<uint8_t> meta(static_cast<size_t>(meta_size));
  VT_RETURN_IF_ERROR(read_at(meta_offset, meta));
  if (XXH3_64bits(meta.data(), meta.size()) != get_u64(h + kOffMetadataChecksum))
    return corrupt("metadata checksum mismatch");
  metadata_.assign(meta.begin(), meta.end());
  return Status::Ok();
}

Status PageFileReaderImpl::parse_layers(uint64_t pos, uint64_t end) {
  for (size_t i = 0; i < layers_.size(); ++i) {
    const std::string which = "layer " + std::to_string(i);
    if (end - pos < kLayerRecordFixedBytes) return corrupt(which + " record overruns the header");
    const uint8_t* p = header_.data() + pos;
    LayerSpec& l = layers_[i];
    l.semantic = LayerSemantic(p[0]);
    l.channels = p[1];
    l.texel_type = TexelType(p[2]);
    l.codec = PageCodec(p[3]);
    l.runtime_format = RuntimeFormat(p[4]);
    l.color_space = ColorSpace(p[5]);
    l.address_mode = AddressMode(p[6]);
    const uint64_t name_size = p[7];
    const uint64_t tables_size = get_u32(p + 8);
    if (get_u32(p + 12) != 0) return corrupt(which + ": reserved field is not zero");
    if (tables_size > kMaxCodecTablesBytes) return corrupt(which + ": codec tables too large");
    const uint64_t record = layer_record_bytes(name_size, tables_size);
    if (record > end - pos) return corrupt(which + " record overruns the header");
    const uint8_t* name = p + kLayerRecordFixedBytes;
    l.name.assign(reinterpret_cast<const char*>(name), size_t(name_size));
    l.codec_tables.assign(name + name_size, name + name_size + tables_size);
    std::string problem = layer_problem(l);
    if (problem.empty() && l.codec == PageCodec::kDct && geometry_.page_size() % 8 != 0)
      problem = "dct pages need a page size that is a multiple of 8";
    for (size_t j = 0; j < i && problem.empty(); ++j)
      if (layers_[j].name == l.name) problem = "name used by layer " + std::to_string(j);
    if (!problem.empty()) return corrupt(which + ": " + problem);
    pos += record;
  }
  if (pos != end) return corrupt("layer table does not end at the header checksum");
  for (size_t i = 0; i < layers_.size(); ++i) {
    auto codec = LayerCodec::create(layers_[i], geometry_.page_size());
    if (!codec.ok()) return corrupt("layer " + std::to_string(i) + ": " + codec.status().message());
    codecs_.push_back(std::move(codec).value());
  }
  return Status::Ok();
}

// Every entry is checked once here so that page reads can trust the index afterwards.
Status PageFileReaderImpl::validate_index() {
  struct Extent {
    uint64_t offset, size, slot;
  };
  std::vector<Extent> extents;
  const uint64_t data_end = data_offset_ + data_size_;
  const uint32_t layer_count = uint32_t(layers_.size());
  for (uint64_t slot = 0; slot < entry_count_; ++slot) {
    const uint8_t* p = index_.data() + slot * kEntryBytes;
    const uint32_t layer = uint32_t(slot % layer_count);
    const LayerSpec& spec = layers_[layer];
    auto bad = [&](const std::string& what) {
      return corrupt("index entry " + std::to_string(slot) + " (layer " + std::to_string(layer) +
                     "): " + what);
    };
    if (get_u16(p + 2) != 0) return bad("reserved field is not zero");
    const uint8_t state = p[0];
    if (state == uint8_t(PageState::kAbsent)) {
      for (int i = 1; i < 32; ++i)
        if (p[i] != 0) return bad("absent page with non-zero fields");
    } else if (state == uint8_t(PageState::kConstant)) {
      const uint32_t tb = spec.texel_bytes();
      if (p[1] != 0 || get_u32(p + 4) != 0) return bad("constant page with codec or size");
      for (uint32_t i = tb; i < 16; ++i)
        if (p[8 + i] != 0) return bad("constant value has bytes past the texel");
      if (XXH3_64bits(p + 8, tb) != get_u64(p + 24)) return bad("constant value checksum mismatch");
    } else if (state == uint8_t(PageState::kStored)) {
      if (p[1] != uint8_t(spec.codec)) return bad("page codec differs from the layer codec");
      const uint64_t size = get_u32(p + 4);
      const uint64_t offset = get_u64(p + 8);
      if (get_u64(p + 16) != 0) return bad("reserved field is not zero");
      if (size == 0) return bad("stored page with no bytes");
      if (offset < data_offset_ || offset > data_end || size > data_end - offset)
        return bad("page bytes lie outside the data area");
      if (align_4k_ && offset % kPageAlignment != 0) return bad("page is not 4 KiB aligned");
      if (spec.codec == PageCodec::kRaw && size != decoded_page_bytes(layer))
        return bad("raw page has the wrong size");
      extents.push_back({offset, size, slot});
    } else {
      return bad("unknown page state " + std::to_string(state));
    }
  }
  std::sort(extents.begin(), extents.end(),
            [](const Extent& a, const Extent& b) { return a.offset < b.offset; });
  for (size_t i = 1; i < extents.size(); ++i)
    if (extents[i - 1].offset + extents[i - 1].size > extents[i].offset)
      return corrupt("index entries " + std::to_string(extents[i - 1].slot) + " and " +
                     std::to_string(extents[i].slot) + " overlap in the data area");
  return Status::Ok();
}

}  // namespace

Expected<std::unique_ptr<PageFileReader>> PageFileReader::open(const std::string& path,
                                                               const ReaderOptions& options) {
  auto reader = std::make_unique<PageFileReaderImpl>(path, options);
  Status s = reader->open_and_validate();
  if (!s.ok()) return s.with_context(path);
  return std::unique_ptr<PageFileReader>(std::move(reader));
}

Expected<std::unique_ptr<PageFileReader>> PageFileReader::open(
    std::shared_ptr<const ByteSource> bytes, const std::string& name,
    const ReaderOptions& options) {
  if (!bytes) return Error(ErrorCode::kInvalidArgument, name + ": no byte source");
  auto reader = std::make_unique<PageFileReaderImpl>(name, options, std::move(bytes));
  Status s = reader->open_and_validate();
  if (!s.ok()) return s.with_context(name);
  return std::unique_ptr<PageFileReader>(std::move(reader));
}

}  // namespace vt
