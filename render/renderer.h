// The validation renderer's three passes over one set of meshes, headless, read back to the CPU:
//  - reference: each mesh's own mip-mapped texture, trilinear sampler, anisotropic taps (up to 16);
//  - feedback: one uint32 page request per pixel at reduced resolution (runtime/ format:
//    bits 0-11 page x, 12-23 page y, 24-28 level; 0xFFFFFFFF where nothing was drawn), alpha-
//    tested against what the cache holds;
//  - virtual: page-table lookup and bordered physical-cache sampling with the same filtering.
// Unlit; alpha test where a mesh asks for it. Output is deterministic on lavapipe.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "common/status.h"
#include "format/page_file.h"
#include "format/page_geometry.h"
#include "render/camera.h"
#include "render/vulkan_context.h"
#include "scene/scene.h"

namespace vt::render {

// One vertex as every pass reads it (shaders/mesh.vert locations 0-4). The virtual pass uses
// position and UV only; colour (linear RGBA, vertex colours times nothing else), normal and
// tangent (w = handedness) feed the reference and lit passes.
struct Vertex {
  float x, y, z;
  float u, v;
  float r = 1, g = 1, b = 1, a = 1;
  float nx = 0, ny = 0, nz = 1;
  float tx = 1, ty = 0, tz = 0, tw = 1;
  // The lit reference's UVs of the normal, occlusion, metallic-roughness and emissive textures
  // (kLitTexture*), each through its slot's texCoord and KHR_texture_transform.
  float tex_uv[4][2] = {};
};
enum LitTextureUv : uint32_t { kLitNormalUv, kLitOcclusionUv, kLitMetalRoughUv, kLitEmissiveUv };

// MeshData::alpha_cutoff of a blended material: both renders write its colour premultiplied
// by alpha, as it composites (shaders/common.glsl).
inline constexpr float kAlphaBlended = -2.0f;

struct MeshData {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;   // triangle list
  uint32_t reference_texture = 0;  // index into the reference textures
  float alpha_cutoff = -1.0f;      // < 0: no alpha test; kAlphaBlended: blended
};

// A material texture's own sampler (glTF): addressing per axis and the magnification filter.
struct TextureSampler {
  scene::WrapMode wrap_s = scene::WrapMode::kRepeat;
  scene::WrapMode wrap_t = scene::WrapMode::kRepeat;
  scene::FilterMode mag_filter = scene::FilterMode::kLinear;
};

// An RGBA8 texture with its whole mip chain in Vulkan's sizes (level L is
// max(1, width >> L) x max(1, height >> L)), row-major, tightly packed.
struct ReferenceTexture {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<std::vector<uint8_t>> levels;
  // Without a sampler, `address_mode` wraps or clamps both axes in the shader's taps (as the
  // virtual texture addresses its layer); with one, the sampler addresses each tap instead.
  AddressMode address_mode = AddressMode::kClamp;
  std::optional<TextureSampler> sampler;
  uint32_t max_level = ~0u;  // LOD clamp (the virtual texture's last level, to compare alike)
  // Non-zero for a page file's levels (the exact check's level texture), whose sizes halve with
  // ceil: level L's ceil(levels_width / 2^L) x ceil(levels_height / 2^L) texels lie in the
  // top-left corner of mip L of the padded width x height chain, which a REPEAT sampler reads
  // (the padding holds what the level's edges address), and each level is sampled at its own
  // scale, as the virtual texture samples it (shaders/reference.frag).
  uint32_t levels_width = 0, levels_height = 0;
};

// Builds a mip chain from level 0 by 2x box filtering (odd sizes: the last row/column is
// averaged with itself). `srgb`: the colour channels carry the sRGB curve and are averaged in
// linear light, as the bake filters them (averaging the bytes darkens thin bright lines: an
// emissive sign seen from afar glowed 2.6x brighter baked than in such a reference).
std::vector<std::vector<uint8_t>> box_mip_chain(const uint8_t* rgba, uint32_t width,
                                                uint32_t height, bool srgb = false);

// The Vulkan format of a physical cache holding `f` (RGBA8, R8, RG8, BC1/3/4/5/7, and for
// half-float layers RGBA16F and BC6H unsigned/signed); VK_FORMAT_UNDEFINED otherwise (RGBA32F).
// The frame is RGBA8: an HDR layer shows clamped to [0, 1].
VkFormat cache_vk_format(RuntimeFormat f);
// Bytes of one page_size^2 page in the cache format (0 for an unsupported format).
size_t cache_page_bytes(RuntimeFormat f, uint32_t page_size);

struct VirtualTextureSetup {
  PageGeometry geometry;
  AddressMode address_mode = AddressMode::kClamp;
  RuntimeFormat cache_format = RuntimeFormat::kRgba8;
  uint32_t slots_x = 16;
  uint32_t slots_y = 16;
  // The lighting layer (HDR irradiance, AO in alpha): the feedback and virtual passes show rgb
  // as x / (1 + x) (the atlas check's tone map) and alpha-test nothing.
  bool tone_map = false;
};

// One page's texels (cache format) to put into a physical slot.
struct SlotUpload {
  uint32_t slot_x = 0;
  uint32_t slot_y = 0;
  std::span<const uint8_t> bytes;  // cache_page_bytes()
};

// The page table in runtime/'s layout: per level, pages_x(L) * pages_y(L) RGBA8 entries
// (R, G slot, B resident level, A flags, bit 0 valid), row-major.
struct PageTableLevels {
  std::vector<std::vector<uint8_t>> levels;
};

struct RenderOptions {
  uint32_t width = 1280;
  uint32_t height = 720;
  uint32_t feedback_divisor = 4;  // feedback resolution = size / divisor per axis
};

struct Rgba8Image {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> texels;  // RGBA8 row-major
};

struct ReferenceFrame {
  Rgba8Image color;
  // Per pixel: bit 0 where the surface was drawn (after alpha test); bit 1 where its alpha was
  // within a few steps above the cutoff (VirtualFrame::status bit 30).
  std::vector<uint32_t> covered;
  // Per pixel: distance along the view axis of the surface drawn, 0 where none was.
  std::vector<float> depth;
};

struct FeedbackImage {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint32_t> requests;
};

struct VirtualFrame {
  Rgba8Image color;
  // Per pixel: the kStatus* bits below, bits 0-7 the level wanted, bits 8-15 the coarsest level
  // a fine tap actually sampled (31: nothing resident).
  std::vector<uint32_t> status;
  // The bits the virtual shaders write (shaders/virtual.frag, lit_virtual.frag).
  static constexpr uint32_t kStatusDrawn = 0x80000000u;
  // Alpha-tested with alpha a few steps above the cutoff: a rounding apart from failing it.
  static constexpr uint32_t kStatusAlphaEdge = 0x40000000u;
  static constexpr uint32_t kStatusBorderRead = 0x20000000u;  // a tap read page-border texels
  // A tap of the coarser level read an ancestor of its page (a fallback too).
  static constexpr uint32_t kStatusCoarseFallback = 0x10000000u;
};

// Lit passes (shaders/lit.glsl): metal-roughness shading with a key and a fill light fixed
// relative to the camera, ambient, emissive added. The inputs, in cache order.
enum class LitInput : uint32_t { kAlbedo, kNormal, kOrm, kEmissive };
inline constexpr uint32_t kLitInputCount = 4;

// One material's extra textures for the lit reference pass, beside its reference texture (the
// albedo). Each a ReferenceTexture (RGBA8 mip chain); a 1 x 1 one where the material has none.
struct LitMaterial {
  ReferenceTexture normal;  // tangent-space normal map as stored (n * 0.5 + 0.5)
  // Roughness (G) and metallic (B) with the factors applied, R 1; occlusion (R, strength
  // applied) apart, since glTF lets it read another UV set.
  ReferenceTexture orm;
  ReferenceTexture occlusion;
  ReferenceTexture emissive;  // sRGB; times emissive_scale (linear)
  float emissive_scale[3] = {0, 0, 0};
  float normal_scale = 1.0f;
  bool has_normal_map = false;
  bool two_channel_normal = false;  // z reconstructed from x and y
};

// What one lit frame is lit with (world space) and which inputs it takes from the materials
// or layers: a bit (1 << LitInput) per input; inputs left out take fixed values on both passes
// (vertex normal; occlusion 1, roughness 0.5, metallic 0; no emission). Albedo is always used.
struct LitFrameOptions {
  float eye[3] = {0, 0, 0};
  float key_dir[3] = {0, 0, 1};   // towards the key light
  float fill_dir[3] = {0, 0, 1};  // towards the fill light
  float key = 1.4f, fill = 0.45f, ambient = 0.1f;
  uint32_t inputs = 0;
  bool shading_normals = false;  // write the shading normal (n * 0.5 + 0.5), not a colour
};

class Renderer {
 public:
  // `ctx` must outlive the renderer.
  static Expected<std::unique_ptr<Renderer>> create(VulkanContext& ctx,
                                                    const RenderOptions& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const RenderOptions& options() const { return options_; }
  uint32_t feedback_width() const;
  uint32_t feedback_height() const;

  // The meshes every pass draws (virtual-texture UVs; reference_texture for the reference pass).
  Status set_meshes(std::span<const MeshData> meshes);
  // Other meshes for the reference pass only (the original scene with its own UVs and
  // textures, where the virtual pass draws the unwrapped scene).
  Status set_reference_meshes(std::span<const MeshData> meshes);
  Status set_reference_textures(std::span<const ReferenceTexture> textures);
  // Creates the physical cache and page-table textures (contents undefined until uploaded).
  Status set_virtual_texture(const VirtualTextureSetup& setup);
  Status upload_slots(std::span<const SlotUpload> pages);
  Status upload_page_table(const PageTableLevels& table);

  Expected<ReferenceFrame> render_reference(const Camera& camera);
  // `frame` rotates which tap each pixel reports and jitters the sub-pixel position.
  Expected<FeedbackImage> render_feedback(const Camera& camera, uint32_t frame);
  Expected<VirtualFrame> render_virtual(const Camera& camera);

  // Lit passes. set_lit_materials: one per reference texture, after set_reference_textures.
  // set_lit_caches: a physical cache per lit input that has a format (the others unused), sharing
  // set_virtual_texture's page table and slots; call after each set_virtual_texture.
  Status set_lit_materials(std::span<const LitMaterial> materials);
  Status set_lit_caches(std::span<const std::optional<RuntimeFormat>, kLitInputCount> formats);
  Status upload_lit_slots(LitInput input, std::span<const SlotUpload> pages);
  Expected<ReferenceFrame> render_lit_reference(const Camera& camera,
                                                const LitFrameOptions& options);
  Expected<VirtualFrame> render_lit_virtual(const Camera& camera, const LitFrameOptions& options);

 private:
  struct Impl;
  explicit Renderer(std::unique_ptr<Impl> impl, const RenderOptions& options);
  std::unique_ptr<Impl> impl_;
  RenderOptions options_;
};

}  // namespace vt::render
