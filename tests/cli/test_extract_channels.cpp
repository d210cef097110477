// End-to-end: `vtbake extract -o X.png` writes 2- and 4-channel layers byte for byte, whether
// the last channel is a colour layer's (unassociated) alpha or data (normal XY, custom).
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <string>
#include <vector>

#include "format/page_file.h"
#include "tests/cli/cli_test_util.h"
#include "tests/format/page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

// A one-level file (one 12x12 page) whose only layer holds `texels` (channels bytes a texel).
std::string one_layer_file(LayerSpec spec, const std::vector<uint8_t>& texels) {
  PageFileDesc desc;
  desc.geometry = {12, 12, 12, 2};
  desc.layers = {spec};
  const PageGeometry& g = desc.geometry;
  const std::string path = temp_path(spec.name + ".vtpf");
  auto w = PageFileWriter::create(path, desc);
  EXPECT_TRUE(w.ok());
  auto page = cut_page(texels, g.width, g.height, spec.channels, g, {0, 0, 0});
  EXPECT_TRUE((*w)->add_page({0, 0, 0}, 0, page).ok());
  EXPECT_TRUE((*w)->finish().ok());
  return path;
}

// The PNG's bytes as stored: OpenImageIO would otherwise premultiply alpha on reading.
std::vector<uint8_t> read_png(const std::string& path, int channels) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  EXPECT_EQ(in->spec().nchannels, channels);
  std::vector<uint8_t> out(size_t(in->spec().width) * in->spec().height * channels);
  EXPECT_TRUE(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, out.data()));
  return out;
}

struct Case {
  const char* name;
  LayerSemantic semantic;
  uint8_t channels;
};

TEST(CliExtract, TwoAndFourChannelLayersToPngAreExact) {
  const Case cases[] = {{"normal", LayerSemantic::kNormal, 2},
                        {"albedo", LayerSemantic::kAlbedo, 4},
                        {"albedo_grey", LayerSemantic::kAlbedo, 2},
                        {"custom", LayerSemantic::kCustom, 4}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    LayerSpec spec = layer(c.name, c.channels, TexelType::kU8, PageCodec::kRaw);
    spec.semantic = c.semantic;
    std::vector<uint8_t> texels = random_levels({12, 12, 12, 2}, c.channels, 7)[0];
    // The normal texel (0.490, 0.502) and texels whose last channel is 0 or small.
    texels[0] = 125, texels[1] = 128;
    texels[c.channels] = 200, texels[2 * c.channels - 1] = 0;
    texels[2 * c.channels] = 255, texels[3 * c.channels - 1] = 3;
    const std::string file = one_layer_file(spec, texels);
    const std::string png = temp_path(std::string(c.name) + ".png");
    RunResult r = run_vtbake("-q extract " + file + " --level 0 -o " + png, true);
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_EQ(read_png(png, c.channels), texels);
  }
}

}  // namespace
}  // namespace vt
