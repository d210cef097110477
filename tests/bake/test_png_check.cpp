// The PNG chunk check that runs before OpenImageIO (bake/png_check.h): damaged and truncated
// files give one message naming the file and the chunk, so libpng never prints its own line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "bake/image_source.h"
#include "bake/png_check.h"
#include "tests/process_temp_dir.h"

namespace vt {
namespace {

namespace fs = std::filesystem;

std::string write_png(const std::string& name) {
  const fs::path dir = test::process_temp_dir("vtbake_png_check");
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  auto out = OIIO::ImageOutput::create(path);
  EXPECT_TRUE(out);
  OIIO::ImageSpec spec(16, 8, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");  // an sRGB/gAMA ancillary chunk before IDAT
  std::vector<uint8_t> texels(16 * 8 * 3);
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = uint8_t(i * 7);
  EXPECT_TRUE(out->open(path, spec));
  EXPECT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texels.data()));
  out->close();
  return path;
}

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

TEST(PngCheck, CleanFileAndOtherFormatsPass) {
  const std::string png = write_png("clean.png");
  EXPECT_TRUE(check_png_chunks(png).ok());
  EXPECT_TRUE(open_image_file(png).ok());
  const std::string other = png + ".txt";
  write(other, "not an image");
  EXPECT_TRUE(check_png_chunks(other).ok());  // no signature: the image reader decides
  EXPECT_TRUE(check_png_chunks(png + ".missing").ok());
}

TEST(PngCheck, DamagedCriticalChunkNamesTheChunk) {
  const std::string png = write_png("flip.png");
  std::string b = read(png);
  const size_t idat = b.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  b[idat + 6] = char(~b[idat + 6]);
  write(png, b);
  const Status s = check_png_chunks(png);
  EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
  const std::string at = std::to_string(idat - 4);
  EXPECT_EQ(s.message().rfind(png + ": corrupt PNG: chunk 'IDAT' at byte " + at + ": CRC 0x", 0),
            0u)
      << s.message();
  EXPECT_NE(s.message().find("computed (damaged data)"), std::string::npos);
  // open_image_file says the same, before OpenImageIO and libpng see the file.
  auto opened = open_image_file(png);
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.status().message(), s.message());
}

TEST(PngCheck, DamagedAncillaryChunkIsIgnoredAsLibpngDoes) {
  const std::string png = write_png("ancillary.png");
  std::string b = read(png);
  const size_t ihdr_end = 8 + 8 + 13 + 4;
  // A tEXt chunk with a wrong CRC right after IHDR.
  const std::string text = std::string("\0\0\0\4tEXtabcd\0\0\0\0", 16);
  b.insert(ihdr_end, text);
  write(png, b);
  EXPECT_TRUE(check_png_chunks(png).ok());
}

TEST(PngCheck, TruncatedFileSaysSo) {
  const std::string png = write_png("short.png");
  std::string b = read(png);
  const size_t idat = b.find("IDAT");
  write(png, b.substr(0, idat + 10));
  Status s = check_png_chunks(png);
  EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
  EXPECT_NE(s.message().find(": corrupt PNG: chunk 'IDAT' at byte " + std::to_string(idat - 4) +
                             " claims "),
            std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("(truncated?)"), std::string::npos);
  // Cut after a whole chunk: no IEND.
  write(png, b.substr(0, b.find("IEND") - 4));
  s = check_png_chunks(png);
  EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
  EXPECT_NE(s.message().find("(no IEND chunk)"), std::string::npos) << s.message();
  // Something other than IHDR first.
  std::string swapped = b;
  swapped.replace(12, 4, "IHDX");
  write(png, swapped);
  s = check_png_chunks(png);
  EXPECT_NE(s.message().find("chunk 'IHDX' at byte 8: the first chunk is not IHDR"),
            std::string::npos)
      << s.message();
}

}  // namespace
}  // namespace vt
