// The validation renderer on a synthetic scene (a ground quad and a cube sharing one procedural
// virtual texture): the page file is written here with the format writer (raw codec, levels by
// a 2x box filter, borders from the level images), streamed through the runtime and rendered
// both ways. Skips cleanly where no Vulkan device exists.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "codec/bc.h"
#include "common/half.h"
#include "format/page_file.h"
#include "render/renderer.h"
#include "render/report.h"
#include "render/scene_draws.h"
#include "render/validate.h"
#include "render/vulkan_context.h"
#include "runtime/page_source.h"
#include "runtime/streamer.h"
#include "scene/scene.h"

namespace vt::render {
namespace {

constexpr uint32_t kWidth = 256;
constexpr uint32_t kHeight = 192;

VulkanContext* vulkan() {
  static Expected<std::unique_ptr<VulkanContext>> ctx = VulkanContext::create();
  return ctx.ok() ? ctx->get() : nullptr;
}

std::string vulkan_error() {
  auto ctx = VulkanContext::create();
  return ctx.ok() ? "" : ctx.status().message();
}

#define REQUIRE_VULKAN() \
  if (!vulkan()) GTEST_SKIP() << "no Vulkan device: " << vulkan_error()

PageGeometry test_geometry() {
  PageGeometry g;
  g.width = 1024;
  g.height = 1024;
  g.payload = 120;
  g.border = 4;
  return g;
}

uint32_t hash2(uint32_t x, uint32_t y) {
  uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  return h ^ (h >> 15);
}

// What the synthetic bake looks like: opaque and clamped by default; optionally with round
// alpha holes (alpha-tested material) or wrapped addressing (the ground quad repeats it).
struct Look {
  bool alpha_holes = false;
  AddressMode mode = AddressMode::kClamp;
  int key() const { return (alpha_holes ? 1 : 0) + 2 * int(mode); }
};

// Smooth ramps (so a wrong level or offset shows) plus 8-texel value-noise cells (so any page
// differs from any other).
std::vector<uint8_t> make_texture(uint32_t w, uint32_t h, const Look& look) {
  std::vector<uint8_t> t(size_t(w) * h * 4);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      uint8_t* p = &t[(size_t(y) * w + x) * 4];
      uint32_t n = hash2(x / 8, y / 8);
      p[0] = uint8_t(std::min(255u, x * 200 / w + (n & 31)));
      p[1] = uint8_t(std::min(255u, y * 200 / h + ((n >> 8) & 31)));
      p[2] = uint8_t(64 + ((n >> 16) & 127));
      p[3] = 255;
      if (look.alpha_holes) {
        int dx = int(x % 128) - 64, dy = int(y % 128) - 64;
        p[3] = dx * dx + dy * dy < 40 * 40 ? 0 : 255;
      }
    }
  }
  return t;
}

struct Levels {
  std::vector<std::vector<uint8_t>> images;  // full Vulkan mip chain, RGBA8
};

const Levels& levels(const Look& look = {}) {
  static Levels cache[4];
  Levels& l = cache[look.key()];
  if (l.images.empty()) {
    PageGeometry g = test_geometry();
    std::vector<uint8_t> base = make_texture(g.width, g.height, look);
    l.images = box_mip_chain(base.data(), g.width, g.height);
  }
  return l;
}

enum class Fault { kNone, kZeroBorders, kSwappedPages, kSwappedChannels, kOpaqueAlpha };

// Page texels (RGBA8, page_size^2) cut from the level images, borders from the true neighbours.
std::vector<uint8_t> page_texels(const PageGeometry& g, const PageId& id, Fault fault,
                                 const Look& look) {
  const uint32_t ps = g.page_size();
  const uint32_t lw = g.level_width(id.level), lh = g.level_height(id.level);
  const std::vector<uint8_t>& img = levels(look).images[id.level];
  std::vector<uint8_t> out(size_t(ps) * ps * 4);
  for (uint32_t j = 0; j < ps; ++j) {
    int64_t ty = address_texel(g.page_origin_y(id) + j, lh, look.mode);
    for (uint32_t i = 0; i < ps; ++i) {
      int64_t tx = address_texel(g.page_origin_x(id) + i, lw, look.mode);
      const uint8_t* s = &img[(size_t(ty) * lw + size_t(tx)) * 4];
      uint8_t* d = &out[(size_t(j) * ps + i) * 4];
      bool border = i < g.border || j < g.border || i >= ps - g.border || j >= ps - g.border;
      for (int c = 0; c < 4; ++c) d[c] = s[c];
      if (fault == Fault::kZeroBorders && border) d[0] = d[1] = d[2] = 0;
      if (fault == Fault::kSwappedChannels) std::swap(d[0], d[2]);
      if (fault == Fault::kOpaqueAlpha) d[3] = 255;  // the bake dropped the alpha channel
    }
  }
  return out;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::path(testing::TempDir()) / ("vt_render_" + name + ".vtpf")).string();
}

// Writes the synthetic bake (raw codec) with an optional fault.
std::string write_bake(const std::string& name, RuntimeFormat runtime, Fault fault,
                       const Look& look = {}) {
  PageFileDesc desc;
  desc.geometry = test_geometry();
  LayerSpec layer;
  layer.name = "albedo";
  layer.channels = 4;
  layer.codec = PageCodec::kRaw;
  layer.runtime_format = runtime;
  layer.address_mode = look.mode;
  desc.layers.push_back(layer);
  const std::string path = temp_path(name);
  auto writer = PageFileWriter::create(path, desc);
  EXPECT_TRUE(writer.ok()) << writer.status().message();
  const PageGeometry& g = desc.geometry;
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    for (uint32_t y = 0; y < g.pages_y(l); ++y) {
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        PageId id{l, x, y};
        PageId src = id;
        // A wrong page in the index: at every level, the page a quarter across and half down
        // (on the ground quad) holds its right neighbour's data.
        if (fault == Fault::kSwappedPages && x == g.pages_x(l) / 4 && y == g.pages_y(l) / 2 &&
            g.pages_x(l) > 1) {
          src.x = x + 1;
        }
        EXPECT_TRUE((*writer)->add_page(id, 0, page_texels(g, src, fault, look)).ok());
      }
    }
  }
  Status s = (*writer)->finish();
  EXPECT_TRUE(s.ok()) << s.message();
  return path;
}

Vertex vtx(float x, float y, float z, float u, float v) {
  return {x, y, z, u, v};
}

// Ground quad on u in [0, 0.5]; a unit cube whose faces fill a 2 x 3 grid of cells on
// u in [0.5, 1].
std::vector<MeshData> make_scene(const Look& look = {}) {
  std::vector<MeshData> meshes(2);
  MeshData& quad = meshes[0];
  // Wrapped: the quad shows the whole texture 2 x 2 times, across its seams.
  const float qu = look.mode == AddressMode::kWrap ? 2.0f : 0.5f;
  const float qv = look.mode == AddressMode::kWrap ? 2.0f : 1.0f;
  quad.vertices = {vtx(-2, 0, -2, 0, 0), vtx(2, 0, -2, qu, 0), vtx(2, 0, 2, qu, qv),
                   vtx(-2, 0, 2, 0, qv)};
  if (look.alpha_holes) quad.alpha_cutoff = 0.5f;
  quad.indices = {0, 1, 2, 0, 2, 3};
  MeshData& cube = meshes[1];
  // Each face: origin corner, two edge vectors (unit cube from (-0.5, 0, -0.5)).
  const float faces[6][9] = {
      {-0.5f, 0, 0.5f, 1, 0, 0, 0, 1, 0},  {0.5f, 0, -0.5f, -1, 0, 0, 0, 1, 0},
      {0.5f, 0, 0.5f, 0, 0, -1, 0, 1, 0},  {-0.5f, 0, -0.5f, 0, 0, 1, 0, 1, 0},
      {-0.5f, 1, 0.5f, 1, 0, 0, 0, 0, -1}, {-0.5f, 0, -0.5f, 1, 0, 0, 0, 0, 1}};
  for (uint32_t f = 0; f < 6; ++f) {
    const float* o = faces[f];
    float u0 = 0.5f + 0.25f * float(f % 2), v0 = float(f / 2) / 3.0f;
    uint32_t base = uint32_t(cube.vertices.size());
    for (int c = 0; c < 4; ++c) {
      float a = (c == 1 || c == 2) ? 1.0f : 0.0f, b = (c >= 2) ? 1.0f : 0.0f;
      cube.vertices.push_back(vtx(o[0] + a * o[3] + b * o[6], o[1] + a * o[4] + b * o[7],
                                  o[2] + a * o[5] + b * o[8], u0 + a * 0.25f, v0 + b / 3.0f));
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) cube.indices.push_back(base + i);
  }
  return meshes;
}

std::vector<Camera> views() {
  return orbit_views({-2, 0, -2}, {2, 1, 2}, 4, float(kWidth) / float(kHeight));
}

std::unique_ptr<Renderer> make_renderer(const Look& look = {}) {
  RenderOptions o;
  o.width = kWidth;
  o.height = kHeight;
  auto r = Renderer::create(*vulkan(), o);
  EXPECT_TRUE(r.ok()) << r.status().message();
  if (!r.ok()) return nullptr;
  std::vector<MeshData> scene = make_scene(look);
  EXPECT_TRUE((*r)->set_meshes(scene).ok());
  ReferenceTexture tex;
  tex.width = test_geometry().width;
  tex.height = test_geometry().height;
  tex.levels = levels(look).images;
  tex.address_mode = look.mode;
  tex.max_level = test_geometry().level_count() - 1;
  Status s = (*r)->set_reference_textures(std::span(&tex, 1));
  EXPECT_TRUE(s.ok()) << s.message();
  return std::move(*r);
}

struct Bake {
  std::shared_ptr<const PageSource> source;
  std::unique_ptr<Streamer> streamer;
};

std::shared_ptr<const PageSource> open_source(const std::string& path) {
  auto reader = PageFileReader::open(path);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  if (!reader.ok()) return nullptr;
  auto source = make_page_file_source(std::shared_ptr<const PageFileReader>(std::move(*reader)));
  EXPECT_TRUE(source.ok()) << source.status().message();
  if (!source.ok()) return nullptr;
  return std::shared_ptr<const PageSource>(std::move(*source));
}

Bake open_bake(const std::string& path) {
  Bake b;
  b.source = open_source(path);
  if (!b.source) return b;
  StreamerOptions so;
  so.slots_x = 16;
  so.slots_y = 16;
  auto streamer = Streamer::create(b.source, so);
  EXPECT_TRUE(streamer.ok()) << streamer.status().message();
  if (streamer.ok()) b.streamer = std::move(*streamer);
  return b;
}

struct ViewRun {
  ConvergeResult converge;
  ViewMetrics metrics;
  ReferenceFrame reference;
  VirtualFrame frame;
};

// Converges every view on a fresh streamer over `path` and compares with the reference.
// `tamper` may alter the page table before the final pass.
std::vector<ViewRun> run_views(const std::string& path,
                               void (*tamper)(Renderer&, const Streamer&) = nullptr,
                               const Look& look = {}) {
  std::vector<ViewRun> runs;
  std::unique_ptr<Renderer> renderer = make_renderer(look);
  if (!renderer) return runs;
  for (const Camera& cam : views()) {
    // A cold cache per view, so frames-to-converge measures each view alone.
    Bake bake = open_bake(path);
    if (!bake.streamer) return runs;
    auto setup = virtual_setup_for(*bake.streamer, 0, look.mode);
    EXPECT_TRUE(setup.ok()) << setup.status().message();
    Status s = renderer->set_virtual_texture(*setup);
    EXPECT_TRUE(s.ok()) << s.message();
    ViewRun run;
    auto c = converge_view(*renderer, *bake.streamer, cam);
    EXPECT_TRUE(c.ok()) << c.status().message();
    if (!c.ok()) return runs;
    run.converge = *c;
    if (tamper) tamper(*renderer, *bake.streamer);
    auto frame = renderer->render_virtual(cam);
    auto ref = renderer->render_reference(cam);
    EXPECT_TRUE(frame.ok() && ref.ok());
    if (!frame.ok() || !ref.ok()) return runs;
    run.frame = std::move(*frame);
    run.reference = std::move(*ref);
    auto m = compare_view(run.reference, run.frame);
    EXPECT_TRUE(m.ok());
    run.metrics = *m;
    runs.push_back(std::move(run));
  }
  return runs;
}

// Views that fail the default thresholds of `format`.
int failing_views(const std::vector<ViewRun>& runs, RuntimeFormat format) {
  int n = 0;
  for (const ViewRun& r : runs)
    n += check_view(r.metrics, default_thresholds(format)).empty() ? 0 : 1;
  return n;
}

void print_runs(const char* name, const std::vector<ViewRun>& runs) {
  for (size_t i = 0; i < runs.size(); ++i) {
    const ViewRun& r = runs[i];
    std::printf(
        "%s view %zu: mismatch %.4f psnr %.2f dB tile %.2f dB ssim %.4f coarser %.4f frames %u "
        "pages %u px "
        "%llu\n",
        name, i, r.metrics.coverage_mismatch_share, r.metrics.psnr_rgb, r.metrics.worst_tile_psnr,
        r.metrics.ssim, r.metrics.coarser_share, r.converge.frames_to_converge,
        r.converge.pages_uploaded, (unsigned long long)r.metrics.pixels);
  }
}

TEST(RenderContext, CreatesOrExplains) {
  auto ctx = VulkanContext::create();
  if (!ctx.ok()) {
    EXPECT_EQ(ctx.status().code(), ErrorCode::kUnsupported) << ctx.status().message();
    EXPECT_NE(ctx.status().message().find("vulkan"), std::string::npos);
    GTEST_SKIP() << ctx.status().message();
  }
  EXPECT_FALSE((*ctx)->device_name().empty());
  ImageDesc bad;
  bad.width = 0;
  EXPECT_EQ((*ctx)->create_image(bad).status().code(), ErrorCode::kInvalidArgument);
}

TEST(Renderer, RejectsBadOptionsAndMeshes) {
  REQUIRE_VULKAN();
  RenderOptions o;
  o.width = 0;
  EXPECT_EQ(Renderer::create(*vulkan(), o).status().code(), ErrorCode::kInvalidArgument);
  o.width = 64;
  o.height = 64;
  auto r = Renderer::create(*vulkan(), o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  MeshData m;
  m.vertices = {vtx(0, 0, 0, 0, 0)};
  m.indices = {0, 0, 1};
  EXPECT_EQ((*r)->set_meshes(std::span(&m, 1)).code(), ErrorCode::kInvalidArgument);
  // No reference texture set for the mesh: a clear error, not a crash.
  m.indices = {0, 0, 0};
  ASSERT_TRUE((*r)->set_meshes(std::span(&m, 1)).ok());
  EXPECT_FALSE((*r)->render_reference(Camera{}).ok());
  EXPECT_FALSE((*r)->render_virtual(Camera{}).ok());  // no virtual texture yet
}

// Resident memory of this process in bytes (Linux), 0 where unknown.
uint64_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  uint64_t pages = 0, resident = 0;
  if (!(statm >> pages >> resident)) return 0;
  return resident * uint64_t(sysconf(_SC_PAGESIZE));
}

// A lit pass draws each material with its own push constants and descriptor set. lavapipe (Mesa
// 22.3) compiled a fragment shader anew for every such draw whose push constants or uniforms
// steer a branch, and kept each: about 1 MB and 5-10 ms a draw, so validate's lit passes over a
// 372-mesh track grew 1 GB a view. The branches now read flat inputs; passes after the first
// must cost no memory.
TEST(Renderer, LitPassesOverManyMaterialsKeepTheirMemory) {
  REQUIRE_VULKAN();
  constexpr uint32_t kMaterials = 150;
  RenderOptions o;
  o.width = 64;
  o.height = 64;
  auto r = Renderer::create(*vulkan(), o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ReferenceTexture one;  // 1 x 1 white
  one.width = one.height = 1;
  one.levels = {{255, 255, 255, 255}};
  std::vector<MeshData> meshes;
  std::vector<LitMaterial> materials(kMaterials);
  for (uint32_t i = 0; i < kMaterials; ++i) {
    const float x = -1.0f + 2.0f * float(i) / kMaterials, w = 2.0f / kMaterials;
    MeshData m;
    m.vertices = {vtx(x, -1, 0.5f, 0, 0), vtx(x + w, -1, 0.5f, 1, 0), vtx(x + w, 1, 0.5f, 1, 1),
                  vtx(x, 1, 0.5f, 0, 1)};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.reference_texture = i;
    m.alpha_cutoff = i % 3 == 0 ? 0.5f : -1.0f;
    meshes.push_back(std::move(m));
    LitMaterial& lm = materials[i];
    lm.normal = lm.orm = lm.occlusion = lm.emissive = one;
    lm.emissive_scale[0] = float(i) / kMaterials;
    lm.has_normal_map = i % 2 == 0;
  }
  ASSERT_TRUE((*r)->set_meshes(meshes).ok());
  ASSERT_TRUE((*r)->set_reference_textures(std::vector<ReferenceTexture>(kMaterials, one)).ok());
  ASSERT_TRUE((*r)->set_lit_materials(materials).ok());
  LitFrameOptions lit;
  lit.inputs = (1u << uint32_t(LitInput::kNormal)) | (1u << uint32_t(LitInput::kOrm)) |
               (1u << uint32_t(LitInput::kEmissive));
  LitFrameOptions normals = lit;
  normals.shading_normals = true;
  auto passes = [&] {
    for (const LitFrameOptions& f : {lit, normals}) {
      auto frame = (*r)->render_lit_reference(Camera{}, f);
      ASSERT_TRUE(frame.ok()) << frame.status().message();
      size_t lit_pixels = 0;
      for (size_t i = 0; i < frame->covered.size(); ++i) lit_pixels += frame->covered[i] & 1;
      EXPECT_EQ(lit_pixels, frame->covered.size());  // every material drawn
    }
  };
  passes();  // the first pass compiles what the driver keeps
  const uint64_t before = resident_bytes();
  if (before == 0) GTEST_SKIP() << "no /proc/self/statm";
  for (int i = 0; i < 3; ++i) passes();
  const uint64_t after = resident_bytes();
  // Three more pairs of passes: 900 draws, about 900 MB where the driver kept a shader a draw.
  EXPECT_LT(after, before + (uint64_t(64) << 20))
      << (after - before) / 1024 << " KiB grown over 900 draws";
}

// A full-screen quad showing uv [0, 0.75]^2 at 3 level-0 texels per pixel wants level 1
// (log2 3 = 1.58) everywhere, and over the screen asks for exactly the 4 x 4 pages of level 1
// that cover level-1 texels [0, 384).
TEST(Renderer, FeedbackRequestsTheAnalyticLevel) {
  REQUIRE_VULKAN();
  RenderOptions o;
  o.width = 256;
  o.height = 256;
  o.feedback_divisor = 4;
  auto r = Renderer::create(*vulkan(), o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  MeshData quad;
  quad.vertices = {vtx(-1, -1, 0.5f, 0, 0), vtx(1, -1, 0.5f, 0.75f, 0),
                   vtx(1, 1, 0.5f, 0.75f, 0.75f), vtx(-1, 1, 0.5f, 0, 0.75f)};
  quad.indices = {0, 1, 2, 0, 2, 3};
  ASSERT_TRUE((*r)->set_meshes(std::span(&quad, 1)).ok());
  VirtualTextureSetup setup;
  setup.geometry = test_geometry();
  ASSERT_TRUE((*r)->set_virtual_texture(setup).ok());
  for (uint32_t frame = 0; frame < 4; ++frame) {
    auto fb = (*r)->render_feedback(Camera{}, frame);
    ASSERT_TRUE(fb.ok()) << fb.status().message();
    ASSERT_EQ(fb->requests.size(), 64u * 64u);
    std::vector<int> seen(16, 0);
    for (uint32_t v : fb->requests) {
      ASSERT_NE(v, 0xFFFFFFFFu);
      ASSERT_EQ(v >> 24, 1u) << std::hex << v;
      uint32_t x = v & 0xFFF, y = (v >> 12) & 0xFFF;
      ASSERT_LT(x, 4u);
      ASSERT_LT(y, 4u);
      seen[y * 4 + x]++;
    }
    for (int s : seen) EXPECT_GT(s, 0);
  }
}

TEST(Renderer, NothingResidentIsLoudNotUndefined) {
  REQUIRE_VULKAN();
  std::unique_ptr<Renderer> r = make_renderer();
  ASSERT_TRUE(r);
  VirtualTextureSetup setup;
  setup.geometry = test_geometry();
  ASSERT_TRUE(r->set_virtual_texture(setup).ok());
  auto frame = r->render_virtual(views()[0]);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  uint64_t covered = 0, unresident = 0;
  for (size_t i = 0; i < frame->status.size(); ++i) {
    if (!(frame->status[i] & 0x80000000u)) continue;
    ++covered;
    if (((frame->status[i] >> 8) & 0xFF) == 31) ++unresident;
  }
  EXPECT_GT(covered, 1000u);
  EXPECT_EQ(unresident, covered);
}

TEST(Validate, CorrectBakeMatchesReference) {
  REQUIRE_VULKAN();
  auto runs = run_views(write_bake("good", RuntimeFormat::kRgba8, Fault::kNone));
  ASSERT_EQ(runs.size(), 4u);
  print_runs("rgba8", runs);
  for (const ViewRun& r : runs) {
    EXPECT_TRUE(r.converge.converged);
    EXPECT_GT(r.converge.frames_to_converge, 0u);
    EXPECT_EQ(r.converge.load_errors, 0u);
    EXPECT_GT(r.metrics.pixels, 2000u);
    EXPECT_GT(r.metrics.ssim, 0.99);
    EXPECT_LT(r.metrics.coarser_share, 0.01);
    EXPECT_EQ(r.metrics.unresident_pixels, 0u);
    for (const std::string& why : check_view(r.metrics, default_thresholds(RuntimeFormat::kRgba8)))
      ADD_FAILURE() << why;
  }
}

// Alpha-tested holes: both paths discard the same pixels (they filter alike), so the background
// shows through the ground quad and the views still pass.
TEST(Validate, AlphaTestedMaterialMatchesReference) {
  REQUIRE_VULKAN();
  Look look;
  look.alpha_holes = true;
  auto runs =
      run_views(write_bake("alpha", RuntimeFormat::kRgba8, Fault::kNone, look), nullptr, look);
  ASSERT_EQ(runs.size(), 4u);
  print_runs("alpha", runs);
  EXPECT_EQ(failing_views(runs, RuntimeFormat::kRgba8), 0);
  auto opaque = run_views(write_bake("alpha_off", RuntimeFormat::kRgba8, Fault::kNone));
  ASSERT_EQ(opaque.size(), 4u);
  for (size_t v = 0; v < runs.size(); ++v) {
    auto covered = [](const VirtualFrame& f) {
      return std::count_if(f.status.begin(), f.status.end(),
                           [](uint32_t s) { return (s & 0x80000000u) != 0; });
    };
    // Holes only where the ground shows; the distant view may see too little of it.
    if (v != 2) {
      EXPECT_LT(covered(runs[v].frame), covered(opaque[v].frame) * 95 / 100) << v;
    }
    EXPECT_EQ(opaque[v].metrics.coverage_mismatch_share, 0.0);
  }
}

// Wrapped addressing: the ground repeats the texture across its seams, where the borders hold
// the texels of the opposite edge.
TEST(Validate, WrappedLayerMatchesReference) {
  REQUIRE_VULKAN();
  Look look;
  look.mode = AddressMode::kWrap;
  auto runs =
      run_views(write_bake("wrap", RuntimeFormat::kRgba8, Fault::kNone, look), nullptr, look);
  ASSERT_EQ(runs.size(), 4u);
  print_runs("wrap", runs);
  EXPECT_EQ(failing_views(runs, RuntimeFormat::kRgba8), 0);
  // Clamped borders on a wrapped layer are a bake fault the seams expose.
  Look clamped_bake;
  auto bad = run_views(write_bake("wrap_bad", RuntimeFormat::kRgba8, Fault::kNone, clamped_bake),
                       nullptr, look);
  print_runs("wrap-with-clamped-borders", bad);
  EXPECT_GT(failing_views(bad, RuntimeFormat::kRgba8), 0);
}

TEST(Validate, Bc1CacheMatchesReference) {
  REQUIRE_VULKAN();
  auto runs = run_views(write_bake("good_bc1", RuntimeFormat::kBc1, Fault::kNone));
  ASSERT_EQ(runs.size(), 4u);
  print_runs("bc1", runs);
  EXPECT_EQ(failing_views(runs, RuntimeFormat::kBc1), 0);
  // BC1 costs accuracy: the uncompressed bound would reject it, so the bounds differ.
  EXPECT_GT(failing_views(runs, RuntimeFormat::kRgba8), 0);
}

// A half-float copy of the synthetic bake (RGB, values up to 1.2: HDR, clamped in the RGBA8
// frame), raw with a BC6H runtime format. With `through_bc6h` every page is stored as the
// real-time BC6H encoder and this codec's decoder give it back, with an RGBA16F runtime format:
// what lavapipe must show when it samples the BC6H blocks itself.
std::string write_half_bake(const std::string& name, bool through_bc6h) {
  PageFileDesc desc;
  desc.geometry = test_geometry();
  LayerSpec layer;
  layer.name = "emissive";
  layer.semantic = LayerSemantic::kEmissive;
  layer.channels = 3;
  layer.texel_type = TexelType::kF16;
  layer.codec = PageCodec::kRaw;
  layer.runtime_format = through_bc6h ? RuntimeFormat::kRgba16f : RuntimeFormat::kBc6hUf16;
  desc.layers.push_back(layer);
  const std::string path = temp_path(name);
  auto writer = PageFileWriter::create(path, desc);
  EXPECT_TRUE(writer.ok()) << writer.status().message();
  const PageGeometry& g = desc.geometry;
  const int ps = int(g.page_size());
  std::vector<uint16_t> half(size_t(ps) * ps * 3), back(half.size());
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc6hUf16, ps, ps));
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    for (uint32_t y = 0; y < g.pages_y(l); ++y) {
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        const PageId id{l, x, y};
        const std::vector<uint8_t> rgba = page_texels(g, id, Fault::kNone, Look{});
        for (size_t t = 0; t < size_t(ps) * ps; ++t)
          for (int c = 0; c < 3; ++c) {
            const float v = float(rgba[t * 4 + c]) / 255.0f;
            half[t * 3 + c] = float_to_half(1.2f * v * v);
          }
        const uint8_t* bytes = reinterpret_cast<const uint8_t*>(half.data());
        if (through_bc6h) {
          EXPECT_TRUE(bc_encode_image(BcFormat::kBc6hUf16, BcQuality::kRealtime, bytes, ps, ps, 3,
                                      blocks.data())
                          .ok());
          EXPECT_TRUE(bc_decode_image(BcFormat::kBc6hUf16, blocks.data(), ps, ps, 3,
                                      reinterpret_cast<uint8_t*>(back.data()))
                          .ok());
          bytes = reinterpret_cast<const uint8_t*>(back.data());
        }
        EXPECT_TRUE(
            (*writer)->add_page(id, 0, std::span<const uint8_t>(bytes, half.size() * 2)).ok());
      }
    }
  }
  Status s = (*writer)->finish();
  EXPECT_TRUE(s.ok()) << s.message();
  return path;
}

// Converges `cam` over the file's streamer (uploads as `options` say) and renders it.
Expected<VirtualFrame> render_half(Renderer& renderer, const std::string& path, const Camera& cam,
                                   const PageFileSourceOptions& options, RuntimeFormat* format) {
  VT_ASSIGN_OR_RETURN(auto reader, PageFileReader::open(path));
  VT_ASSIGN_OR_RETURN(
      auto source,
      make_page_file_source(std::shared_ptr<const PageFileReader>(std::move(reader)), options));
  std::shared_ptr<const PageSource> shared(std::move(source));
  *format = shared->upload_format(0);
  StreamerOptions so;
  so.slots_x = 16;
  so.slots_y = 16;
  VT_ASSIGN_OR_RETURN(auto streamer, Streamer::create(shared, so));
  VT_ASSIGN_OR_RETURN(VirtualTextureSetup setup,
                      virtual_setup_for(*streamer, 0, AddressMode::kClamp));
  VT_RETURN_IF_ERROR(renderer.set_virtual_texture(setup));
  VT_RETURN_IF_ERROR(converge_view(renderer, *streamer, cam).status());
  return renderer.render_virtual(cam);
}

TEST(Validate, Bc6hCacheSamplesAsItsDecodedTexels) {
  REQUIRE_VULKAN();
  if (!vulkan()->supports_sampled_linear(VK_FORMAT_BC6H_UFLOAT_BLOCK))
    GTEST_SKIP() << "the device does not sample BC6H";
  const std::string bc6h = write_half_bake("half_bc6h", false);
  const std::string decoded = write_half_bake("half_bc6h_decoded", true);
  std::unique_ptr<Renderer> renderer = make_renderer();
  ASSERT_TRUE(renderer);
  PageFileSourceOptions as_half;
  as_half.bc6h_as_rgba16f = true;
  for (const Camera& cam : views()) {
    RuntimeFormat f[3];
    auto gpu = render_half(*renderer, bc6h, cam, {}, &f[0]);        // BC6H blocks sampled
    auto cpu = render_half(*renderer, decoded, cam, {}, &f[1]);     // decoded here, RGBA16F
    auto half = render_half(*renderer, bc6h, cam, as_half, &f[2]);  // the halves as stored
    ASSERT_TRUE(gpu.ok()) << gpu.status().message();
    ASSERT_TRUE(cpu.ok()) << cpu.status().message();
    ASSERT_TRUE(half.ok()) << half.status().message();
    EXPECT_EQ(f[0], RuntimeFormat::kBc6hUf16);
    EXPECT_EQ(f[1], RuntimeFormat::kRgba16f);
    EXPECT_EQ(f[2], RuntimeFormat::kRgba16f);
    // Lavapipe's BC6H decode equals this codec's, texel for texel: identical frames (the
    // real-time blocks: modes 11-14; modes 1-10 are checked against the spec in test_bc6h).
    EXPECT_EQ(gpu->color.texels, cpu->color.texels);
    // Against the RGBA16F upload of the stored halves: the real-time encoder's error.
    ReferenceFrame ref{half->color, {}};
    for (const uint32_t st : half->status) ref.covered.push_back(st >> 31);
    auto m = compare_view(ref, *gpu);
    ASSERT_TRUE(m.ok()) << m.status().message();
    std::printf("bc6h vs rgba16f: psnr %.2f dB, worst tile %.2f dB\n", m->psnr_rgb,
                m->worst_tile_psnr);
    // Measured 32.8-37.3 dB over the four views (worst tile 25.3): the 8-texel noise cells put
    // unrelated colours into one block, which one-region real-time blocks cannot hold.
    EXPECT_GT(m->psnr_rgb, 31.0);
  }
}

TEST(Validate, RendersAreBitIdentical) {
  REQUIRE_VULKAN();
  const std::string path = write_bake("determinism", RuntimeFormat::kRgba8, Fault::kNone);
  auto a = run_views(path);
  auto b = run_views(path);
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(b.size(), 4u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].frame.color.texels, b[i].frame.color.texels) << "view " << i;
    EXPECT_EQ(a[i].frame.status, b[i].frame.status) << "view " << i;
    EXPECT_EQ(a[i].reference.color.texels, b[i].reference.color.texels) << "view " << i;
    EXPECT_EQ(a[i].reference.covered, b[i].reference.covered) << "view " << i;
    EXPECT_EQ(a[i].converge.frames_to_converge, b[i].converge.frames_to_converge);
  }
}

// The page table claims each entry's page is one level coarser than the one in its slot.
void off_by_one_level(Renderer& renderer, const Streamer& streamer) {
  PageTable table = streamer.page_table();
  PageTableLevels levels;
  for (uint32_t l = 0; l < table.level_count(); ++l) {
    auto d = table.level_data(l);
    std::vector<uint8_t> level(d.begin(), d.end());
    for (size_t i = 0; i + 3 < level.size(); i += 4) {
      if (level[i + 2] + 1u < table.level_count()) level[i + 2]++;
    }
    levels.levels.push_back(std::move(level));
  }
  EXPECT_TRUE(renderer.upload_page_table(levels).ok());
}

// A faulty bake, cache or page table: every view must fail the thresholds of its cache format.
struct FaultCase {
  const char* name;
  RuntimeFormat runtime;
  Fault fault;
  void (*tamper)(Renderer&, const Streamer&) = nullptr;
  bool alpha_holes = false;
};

const FaultCase kFaultCases[] = {
    {"zero_borders", RuntimeFormat::kRgba8, Fault::kZeroBorders},
    {"zero_borders_bc1", RuntimeFormat::kBc1, Fault::kZeroBorders},
    {"wrong_page", RuntimeFormat::kRgba8, Fault::kSwappedPages},
    {"swapped_bc1", RuntimeFormat::kBc1, Fault::kSwappedChannels},
    {"off_by_one", RuntimeFormat::kRgba8, Fault::kNone, off_by_one_level},
    {"alpha_dropped", RuntimeFormat::kRgba8, Fault::kOpaqueAlpha, nullptr, true},
};

class ValidateFault : public testing::TestWithParam<FaultCase> {};

TEST_P(ValidateFault, EveryViewFails) {
  REQUIRE_VULKAN();
  const FaultCase& c = GetParam();
  Look look;
  look.alpha_holes = c.alpha_holes;
  auto runs = run_views(write_bake(c.name, c.runtime, c.fault, look), c.tamper, look);
  ASSERT_EQ(runs.size(), 4u);
  print_runs(c.name, runs);
  EXPECT_EQ(failing_views(runs, c.runtime), 4);
  // A dropped alpha channel shows as surface where the reference has holes.
  if (c.fault == Fault::kOpaqueAlpha) {
    EXPECT_GT(runs[1].metrics.coverage_mismatch_share, 0.05);
  }
}

INSTANTIATE_TEST_SUITE_P(Validate, ValidateFault, testing::ValuesIn(kFaultCases),
                         [](const testing::TestParamInfo<FaultCase>& info) {
                           return std::string(info.param.name);
                         });

// validate_views over the first `view_count` views of the synthetic bake `name` (RGBA8 cache).
// `slots` per side of the cache.
Expected<ValidationReport> validate_bake(Renderer& renderer, const std::string& name, Fault fault,
                                         size_t view_count, const std::string& out_dir = "",
                                         uint32_t slots = 16) {
  auto source = open_source(write_bake(name, RuntimeFormat::kRgba8, fault));
  if (!source) return Error(ErrorCode::kInternal, "cannot open " + name);
  ValidateOptions options;
  options.streamer.slots_x = options.streamer.slots_y = slots;
  options.out_dir = out_dir;
  std::vector<Camera> cams = views();
  return validate_views(renderer, source, std::span(cams).first(view_count), options);
}

TEST(Validate, WritesImagesAndReport) {
  REQUIRE_VULKAN();
  std::unique_ptr<Renderer> renderer = make_renderer();
  ASSERT_TRUE(renderer);
  const char* keep = std::getenv("VT_RENDER_KEEP_IMAGES");  // a folder to inspect the images
  const std::string dir =
      keep ? keep : (std::filesystem::path(testing::TempDir()) / "vt_render_report").string();
  std::filesystem::create_directories(dir);
  auto report = validate_bake(*renderer, "report", Fault::kNone, 2, dir);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_TRUE(report->passed());
  ASSERT_EQ(report->views.size(), 2u);
  EXPECT_EQ(report->cache_format, "rgba8");
  for (const ViewReport& v : report->views) {
    EXPECT_TRUE(v.failures.empty());
    ASSERT_EQ(v.images.size(), 4u);
    for (const std::string& file : v.images) {
      auto in = OIIO::ImageInput::open(file);
      ASSERT_TRUE(in) << file;
      EXPECT_EQ(in->spec().width, int(kWidth));
      EXPECT_EQ(in->spec().height, int(kHeight));
      EXPECT_EQ(in->spec().nchannels, 3);
    }
  }
  // PNGs are lossless and keep the channel order: the reference on disk is the render.
  {
    auto in = OIIO::ImageInput::open(report->views[0].images[0]);
    ASSERT_TRUE(in);
    std::vector<uint8_t> rgb(size_t(kWidth) * kHeight * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, rgb.data()));
    auto ref = renderer->render_reference(views()[0]);
    ASSERT_TRUE(ref.ok());
    for (size_t i = 0; i < size_t(kWidth) * kHeight; ++i) {
      for (int c = 0; c < 3; ++c) ASSERT_EQ(rgb[i * 3 + c], ref->color.texels[i * 4 + c]) << i;
    }
  }
  const std::string json_path = dir + "/report.json";
  ASSERT_TRUE(write_report_json(json_path, *report).ok());
  std::ifstream f(json_path);
  nlohmann::json doc = nlohmann::json::parse(f);
  EXPECT_EQ(doc["passed"], true);
  ASSERT_EQ(doc["views"].size(), 2u);
  EXPECT_DOUBLE_EQ(doc["views"][0]["psnr_rgb"].get<double>(), report->views[0].metrics.psnr_rgb);
  EXPECT_EQ(doc["views"][1]["frames_to_converge"].get<uint32_t>(),
            report->views[1].converge.frames_to_converge);
}

TEST(Validate, ReportFailsABrokenBake) {
  REQUIRE_VULKAN();
  std::unique_ptr<Renderer> renderer = make_renderer();
  ASSERT_TRUE(renderer);
  auto report = validate_bake(*renderer, "report_bad", Fault::kZeroBorders, 1);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_FALSE(report->passed());
  bool tile = false;
  for (const std::string& why : report->views[0].failures)
    tile |= why.find("tile") != std::string::npos;
  EXPECT_TRUE(tile);
}

// A cache too small for a view's pages cannot converge; the failure says which flag mends it.
TEST(Validate, ACacheTooSmallForTheViewSaysSo) {
  REQUIRE_VULKAN();
  std::unique_ptr<Renderer> renderer = make_renderer();
  ASSERT_TRUE(renderer);
  auto report = validate_bake(*renderer, "report_small_cache", Fault::kNone, 1, "", 2);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_FALSE(report->passed());
  EXPECT_TRUE(report->views[0].converge.thrashing);
  bool named = false;
  for (const std::string& why : report->views[0].failures)
    named |= why.find("do not fit the cache's 2 x 2 slots (a larger --slots)") != std::string::npos;
  EXPECT_TRUE(named) << ::testing::PrintToString(report->views[0].failures);
}

TEST(Report, HeatMapAndDifferenceMap) {
  VirtualFrame f;
  f.color.width = 4;
  f.color.height = 1;
  f.color.texels.assign(16, 0);
  // background, level 0 as wanted, level 2 where level 1 was wanted, nothing resident
  f.status = {0u, 0x80000000u, 0x80000000u | 1u | (2u << 8), 0x80000000u | (31u << 8)};
  Rgba8Image h = residency_heat_map(f);
  ASSERT_EQ(h.texels.size(), 16u);
  EXPECT_EQ(h.texels[0], 0);    // background black
  EXPECT_EQ(h.texels[4], 255);  // level 0 white
  EXPECT_EQ(h.texels[5], 255);
  EXPECT_EQ(h.texels[8], 255);  // coarser: red tint
  EXPECT_LT(h.texels[9], 100);
  EXPECT_EQ(h.texels[12], 255);  // unresident: magenta
  EXPECT_EQ(h.texels[13], 0);
  EXPECT_EQ(h.texels[14], 255);
  Rgba8Image a = f.color, b = f.color;
  b.texels[4 + 1] = 3;    // pixel 1, green off by 3
  b.texels[8 + 2] = 200;  // pixel 2, blue off by 200
  Rgba8Image d = difference_map(a, b, 8);
  EXPECT_EQ(d.texels[0], 0);
  EXPECT_EQ(d.texels[4], 24);
  EXPECT_EQ(d.texels[8], 255);
}

scene::Scene one_triangle_scene() {
  scene::Scene sc;
  sc.source_path = "memory.gltf";
  scene::Primitive p;
  p.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  p.uvs = {{{0, 0}, {1, 0}, {0, 1}}};
  p.indices = {0, 1, 2};
  p.material = 0;
  scene::Mesh mesh;
  mesh.name = "tri";
  mesh.primitives.push_back(p);
  sc.meshes.push_back(mesh);
  scene::Material m;
  m.base_color_factor = {0.5f, 1.0f, 1.0f, 1.0f};
  m.alpha_mode = scene::AlphaMode::kMask;
  m.alpha_cutoff = 0.25f;
  sc.materials.push_back(m);
  scene::Node node;
  node.mesh = 0;
  node.local = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 20, 30, 1};  // translation (10, 20, 30)
  sc.nodes.push_back(node);
  sc.roots = {0};
  return sc;
}

TEST(SceneDraws, FlattensInstancesAndAppliesTheFactor) {
  scene::Scene sc = one_triangle_scene();
  auto virt = virtual_scene_draws(sc);
  ASSERT_TRUE(virt.ok()) << virt.status().message();
  ASSERT_EQ(virt->meshes.size(), 1u);
  EXPECT_EQ(virt->meshes[0].vertices[1].x, 11.0f);
  EXPECT_EQ(virt->meshes[0].vertices[2].y, 21.0f);
  EXPECT_EQ(virt->meshes[0].vertices[1].u, 1.0f);
  EXPECT_EQ(virt->meshes[0].alpha_cutoff, 0.25f);
  EXPECT_EQ(virt->bounds_min.z, 30.0f);
  EXPECT_EQ(virt->bounds_max.x, 11.0f);
  // No atlas UV set 1: the error names the primitive.
  auto missing = virtual_scene_draws(sc, 1);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("mesh 'tri' primitive 0"), std::string::npos);

  auto ref = reference_scene_draws(sc);
  ASSERT_TRUE(ref.ok()) << ref.status().message();
  ASSERT_EQ(ref->textures.size(), 2u);  // the material's and the default material's
  const std::vector<uint8_t>& t = ref->textures[0].levels[0];
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0], 188);  // linear 0.5 stored as sRGB
  EXPECT_EQ(t[1], 255);
  EXPECT_EQ(t[3], 255);
  EXPECT_EQ(ref->meshes[0].reference_texture, 0u);

  sc.meshes[0].primitives[0].uvs[0][1][0] = std::nanf("");
  EXPECT_EQ(virtual_scene_draws(sc).status().code(), ErrorCode::kCorrupt);
}

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// Figures for docs/BENCHMARKS.md, not a test (no assertion on time): run with
//   vt_render_tests --gtest_also_run_disabled_tests --gtest_filter='*Bench*'
// 1280x720, feedback at 320x180, the synthetic bake, per view: medians of 9 passes after warm-up.
TEST(DISABLED_RenderBench, FrameTimes1280x720) {
  REQUIRE_VULKAN();
  std::printf("device: %s\n", vulkan()->device_name().c_str());
  for (RuntimeFormat format : {RuntimeFormat::kRgba8, RuntimeFormat::kBc1}) {
    RenderOptions o;
    o.width = 1280;
    o.height = 720;
    auto r = Renderer::create(*vulkan(), o);
    ASSERT_TRUE(r.ok());
    Renderer& renderer = **r;
    std::vector<MeshData> scene = make_scene();
    ASSERT_TRUE(renderer.set_meshes(scene).ok());
    ReferenceTexture tex;
    tex.width = tex.height = 1024;
    tex.levels = levels().images;
    tex.max_level = test_geometry().level_count() - 1;
    ASSERT_TRUE(renderer.set_reference_textures(std::span(&tex, 1)).ok());
    auto source =
        open_source(write_bake(std::string("bench_") + to_string(format), format, Fault::kNone));
    ASSERT_TRUE(source);
    std::vector<Camera> cams = orbit_views({-2, 0, -2}, {2, 1, 2}, 4, 1280.0f / 720.0f);
    std::printf(
        "| cache | view | feedback ms | stream ms/frame | final ms | reference ms | "
        "frames to converge | pages | PSNR dB | worst tile dB | SSIM | coarser |\n");
    for (size_t v = 0; v < cams.size(); ++v) {
      StreamerOptions so;
      so.slots_x = so.slots_y = 16;
      auto streamer = Streamer::create(source, so);
      ASSERT_TRUE(streamer.ok());
      auto setup = virtual_setup_for(**streamer, 0, AddressMode::kClamp);
      ASSERT_TRUE(setup.ok());
      ASSERT_TRUE(renderer.set_virtual_texture(*setup).ok());
      auto c = converge_view(renderer, **streamer, cams[v]);
      ASSERT_TRUE(c.ok());
      std::vector<double> fb, fin, ref;
      VirtualFrame frame;
      ReferenceFrame reference;
      for (int i = 0; i < 10; ++i) {
        auto t0 = std::chrono::steady_clock::now();
        auto f = renderer.render_feedback(cams[v], uint32_t(i));
        auto t1 = std::chrono::steady_clock::now();
        auto vf = renderer.render_virtual(cams[v]);
        auto t2 = std::chrono::steady_clock::now();
        auto rf = renderer.render_reference(cams[v]);
        auto t3 = std::chrono::steady_clock::now();
        ASSERT_TRUE(f.ok() && vf.ok() && rf.ok());
        if (i == 0) continue;  // warm-up: first use compiles the shaders
        fb.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        fin.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
        ref.push_back(std::chrono::duration<double, std::milli>(t3 - t2).count());
        frame = std::move(*vf);
        reference = std::move(*rf);
      }
      auto m = compare_view(reference, frame);
      ASSERT_TRUE(m.ok());
      std::printf(
          "| %s | %zu | %.1f | %.1f | %.1f | %.1f | %u | %u | %.2f | %.2f | %.4f | %.4f |\n",
          to_string(format), v, median_of(fb), median_of(c->stream_ms), median_of(fin),
          median_of(ref), c->frames_to_converge, c->pages_uploaded, m->psnr_rgb, m->worst_tile_psnr,
          m->ssim, m->coarser_share);
    }
  }
}

}  // namespace
}  // namespace vt::render
