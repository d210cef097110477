// The runtime reads whatever the baker writes: every layer kind a build can produce (semantic x
// source channels x 8-bit or float source x storage codec, which decide the stored channels,
// texel type, codec and runtime format) either streams through the C API, every level-0 page
// arriving with the bytes the page file decodes to, or the baker refuses it with a message.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "bake/build.h"
#include "bake/image_source.h"
#include "format/page_file.h"
#include "format/page_file_c.h"
#include "format/runtime_format.h"
#include "runtime/vt_runtime_c.h"

namespace vt {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kSide = 32;  // 4 x 4 level-0 pages of 8 + 2 * 4 texels

std::shared_ptr<ImageSource> test_image(uint32_t channels, bool is_float) {
  ImageInfo info;
  info.width = info.height = kSide;
  info.channels = channels;
  info.is_float = is_float;
  info.alpha_channel = channels == 2 || channels == 4 ? int(channels) - 1 : -1;
  std::vector<float> texels(size_t(kSide) * kSide * channels);
  for (size_t i = 0; i < texels.size(); ++i) {
    const float v = float((i * 37 + i / channels * 11) % 256) / 255.0f;
    // Float sources carry HDR values in colour channels; alpha stays in [0, 1].
    const bool alpha = int(i % channels) == info.alpha_channel;
    texels[i] = is_float && !alpha ? v * 4.0f : v;
  }
  return std::make_shared<MemoryImageSource>(info, std::move(texels));
}

std::string kind_name(LayerSemantic semantic, uint32_t channels, bool is_float, CodecKind codec,
                      FloatTexels float_texels) {
  static const char* codecs[] = {"dct", "bc", "raw"};
  return std::string(to_string(semantic)) + "_" + std::to_string(channels) +
         (is_float ? "ch_float_" : "ch_u8_") + codecs[int(codec)] +
         (float_texels == FloatTexels::kHalf ? "_half" : "");
}

// Streams every level-0 page of `path` and checks uploads against the file's decoded texels
// where the upload is the texels themselves (float layers as RGBA16F/RGBA32F: widened to 4
// channels).
void expect_streams(const std::string& path, const std::string& kind) {
  vtrt_options o;
  vtrt_default_options(&o);
  o.slots_x = o.slots_y = 5;  // 25 slots for 16 + 4 + 1 pages
  vtrt_streamer* h = nullptr;
  ASSERT_EQ(vtrt_open(path.c_str(), &o, &h), VT_OK) << kind << ": " << vt_last_error();
  vtpf_file* file = nullptr;
  ASSERT_EQ(vtpf_open(path.c_str(), 1, &file), VT_OK) << vt_last_error();
  vtpf_layer_info layer;
  ASSERT_EQ(vtpf_get_layer(file, 0, &layer), VT_OK);
  uint32_t format = 0;
  size_t bytes = 0;
  ASSERT_EQ(vtrt_get_upload_format(h, 0, &format, &bytes), VT_OK);
  const RuntimeFormatInfo* info = runtime_format_info(RuntimeFormat(format));
  ASSERT_NE(info, nullptr) << kind;

  std::vector<uint32_t> feedback;
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 4; ++x) feedback.push_back(VTRT_FEEDBACK(0, x, y));
  std::set<uint32_t> arrived;
  std::vector<uint8_t> texels(layer.decoded_page_bytes);
  for (int frame = 0; frame < 40 && arrived.size() < 16; ++frame) {
    vtrt_frame_stats stats;
    ASSERT_EQ(vtrt_update(h, feedback.data(), feedback.size(), &stats), VT_OK) << vt_last_error();
    ASSERT_EQ(stats.load_errors, 0u) << kind;
    for (uint32_t i = 0; i < vtrt_upload_count(h); ++i) {
      vtrt_upload u;
      ASSERT_EQ(vtrt_get_upload(h, i, 0, &u), VT_OK);
      ASSERT_EQ(u.size, bytes) << kind;
      if (u.level != 0) continue;
      arrived.insert(u.page_y * 4 + u.page_x);
      if (!info->is_float || info->bc) continue;  // BC blocks (BC6H for half layers): not texels
      ASSERT_EQ(vtpf_read_texels(file, 0, u.page_x, u.page_y, 0, texels.data(), texels.size()),
                VT_OK);
      const uint32_t cb = layer.texel_bytes / layer.channels;
      for (size_t t = 0; t < texels.size() / layer.texel_bytes; ++t)
        for (uint32_t c = 0; c < info->channels; ++c) {
          const uint8_t* got = u.data + (t * info->channels + c) * cb;
          if (c < layer.channels) {
            ASSERT_EQ(std::memcmp(got, texels.data() + t * layer.texel_bytes + c * cb, cb), 0)
                << kind << " texel " << t << " channel " << c;
          } else if (cb == 4) {
            float v = 0;
            std::memcpy(&v, got, sizeof v);
            ASSERT_EQ(v, c == 3 ? 1.0f : 0.0f) << kind << " widened channel " << c;
          } else {
            uint16_t v = 0;
            std::memcpy(&v, got, sizeof v);
            ASSERT_EQ(v, c == 3 ? 0x3c00 : 0) << kind << " widened half channel " << c;
          }
        }
    }
    vtrt_wait_idle(h);
  }
  EXPECT_EQ(arrived.size(), 16u) << kind;
  vtpf_close(file);
  vtrt_close(h);
}

TEST(LayerKinds, EveryLayerTheBakerWritesStreams) {
  const fs::path dir =
      fs::temp_directory_path() / ("vtbake_layer_kinds_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::set<std::string> written_kinds, refused;
  for (LayerSemantic semantic :
       {LayerSemantic::kAlbedo, LayerSemantic::kNormal, LayerSemantic::kOrm,
        LayerSemantic::kEmissive, LayerSemantic::kCustom})
    for (uint32_t channels = 1; channels <= 4; ++channels)
      for (bool is_float : {false, true})
        for (CodecKind codec : {CodecKind::kDct, CodecKind::kBc, CodecKind::kRaw})
          for (FloatTexels float_texels : {FloatTexels::kAuto, FloatTexels::kHalf}) {
            // Half storage is for float sources, and does not depend on the codec asked for.
            if (float_texels == FloatTexels::kHalf && (!is_float || codec != CodecKind::kDct))
              continue;
            const std::string kind = kind_name(semantic, channels, is_float, codec, float_texels);
            BuildOptions o;
            LayerInput in;
            in.semantic = semantic;
            in.source = test_image(channels, is_float);
            o.layers.push_back(in);
            o.payload = 8;
            o.threads = 1;
            o.codec.codec = codec;
            o.codec.float_texels = float_texels;
            o.output = (dir / (kind + ".vtpf")).string();
            auto built = build_page_file(o);
            if (!built.ok()) {
              EXPECT_FALSE(built.status().message().empty()) << kind;
              refused.insert(kind);
              continue;
            }
            const LayerSpec& spec = built->layers[0].spec;
            const std::string layer_kind =
                std::to_string(spec.channels) + "ch " + to_string(spec.texel_type) + " " +
                to_string(spec.codec) + " -> " + to_string(spec.runtime_format);
            written_kinds.insert(layer_kind);
            expect_streams(o.output, kind + " (" + layer_kind + ")");
          }
  // Only a one-channel normal map is refused (a normal needs x and y).
  EXPECT_EQ(refused,
            (std::set<std::string>{"normal_1ch_u8_dct", "normal_1ch_u8_bc", "normal_1ch_u8_raw",
                                   "normal_1ch_float_dct", "normal_1ch_float_bc",
                                   "normal_1ch_float_raw", "normal_1ch_float_dct_half"}));
  // The kinds covered, so a new one the baker learns shows up here.
  for (const std::string& k : written_kinds) std::printf("layer kind: %s\n", k.c_str());
  EXPECT_GE(written_kinds.size(), 19u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace vt
