#include "render/renderer.h"

#include "common/srgb.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <functional>
#include <utility>

#include "format/runtime_format.h"
#include "render/shaders.h"

namespace vt::render {
namespace {

#define VT_VK(call) VT_RETURN_IF_ERROR(vk_status((call), #call))

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kUintFormat = VK_FORMAT_R32_UINT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkFormat kPageTableFormat = VK_FORMAT_R8G8B8A8_UINT;

// Mirrors `Push` in shaders/common.glsl.
struct Push {
  float mvp[16];
  float tex[4];
  int32_t vt[4];
  int32_t misc[4];
};
static_assert(sizeof(Push) == 112, "push constants must match shaders/common.glsl");

uint32_t next_pow2(uint32_t v) {
  uint32_t p = 1;
  while (p < v) p <<= 1;
  return p;
}

uint32_t mip_count(uint32_t w, uint32_t h) {
  uint32_t n = 1;
  while ((w >> n) > 0 || (h >> n) > 0) ++n;
  return n;
}

// The lit passes' Vulkan objects, made on first use (no lit pass, no cost).
struct LitState {
  VkDevice dev = VK_NULL_HANDLE;
  VkDescriptorSetLayout ref_set_layout = VK_NULL_HANDLE;
  VkDescriptorSetLayout vt_set_layout = VK_NULL_HANDLE;
  VkPipelineLayout ref_layout = VK_NULL_HANDLE;
  VkPipelineLayout vt_layout = VK_NULL_HANDLE;
  VkPipeline ref_pipe = VK_NULL_HANDLE;
  VkPipeline vt_pipe = VK_NULL_HANDLE;
  VkDescriptorPool ref_pool = VK_NULL_HANDLE;
  VkDescriptorPool vt_pool = VK_NULL_HANDLE;
  VkDescriptorSet vt_set = VK_NULL_HANDLE;
  Buffer frame;  // the LitFrame uniform block (shaders/lit.glsl), host-visible
  Image blank;   // 1 x 1 white: what an unused cache binding reads
  struct Material {
    Image normal, orm, emissive, occlusion;
    VkDescriptorSet set = VK_NULL_HANDLE;
    float emissive_scale[3] = {0, 0, 0};
    float normal_scale = 1.0f;
    int32_t flags = 0;  // bit 0 normal map, bit 1 two-channel normal map
  };
  std::vector<Material> materials;
  std::array<Image, kLitInputCount> caches;
  std::array<std::optional<RuntimeFormat>, kLitInputCount> formats;
  bool ready() const { return ref_pipe != VK_NULL_HANDLE; }
  ~LitState() {
    if (!dev) return;
    for (VkPipeline p : {ref_pipe, vt_pipe})
      if (p) vkDestroyPipeline(dev, p, nullptr);
    for (VkPipelineLayout l : {ref_layout, vt_layout})
      if (l) vkDestroyPipelineLayout(dev, l, nullptr);
    for (VkDescriptorSetLayout l : {ref_set_layout, vt_set_layout})
      if (l) vkDestroyDescriptorSetLayout(dev, l, nullptr);
    for (VkDescriptorPool p : {ref_pool, vt_pool})
      if (p) vkDestroyDescriptorPool(dev, p, nullptr);
  }
};

}  // namespace

std::vector<std::vector<uint8_t>> box_mip_chain(const uint8_t* rgba, uint32_t width,
                                                uint32_t height, bool srgb) {
  float to_linear[256];
  for (int v = 0; v < 256; ++v) to_linear[v] = srgb_to_linear(v / 255.0f);
  std::vector<std::vector<uint8_t>> levels;
  levels.emplace_back(rgba, rgba + size_t(width) * height * 4);
  uint32_t w = width, h = height;
  while (w > 1 || h > 1) {
    uint32_t nw = std::max(1u, w / 2), nh = std::max(1u, h / 2);
    const std::vector<uint8_t>& src = levels.back();
    std::vector<uint8_t> dst(size_t(nw) * nh * 4);
    for (uint32_t y = 0; y < nh; ++y) {
      uint32_t y0 = std::min(2 * y, h - 1), y1 = std::min(2 * y + 1, h - 1);
      for (uint32_t x = 0; x < nw; ++x) {
        uint32_t x0 = std::min(2 * x, w - 1), x1 = std::min(2 * x + 1, w - 1);
        const size_t taps[4] = {(size_t(y0) * w + x0) * 4, (size_t(y0) * w + x1) * 4,
                                (size_t(y1) * w + x0) * 4, (size_t(y1) * w + x1) * 4};
        for (int c = 0; c < 4; ++c) {
          uint8_t& out = dst[(size_t(y) * nw + x) * 4 + c];
          if (srgb && c < 3) {
            float sum = 0;
            for (size_t t : taps) sum += to_linear[src[t + c]];
            out = uint8_t(std::lround(linear_to_srgb(sum * 0.25f) * 255.0f));
          } else {
            uint32_t sum = 0;
            for (size_t t : taps) sum += src[t + c];
            out = uint8_t((sum + 2) / 4);
          }
        }
      }
    }
    levels.push_back(std::move(dst));
    w = nw;
    h = nh;
  }
  return levels;
}

VkFormat cache_vk_format(RuntimeFormat f) {
  static constexpr std::pair<RuntimeFormat, VkFormat> kFormats[] = {
      {RuntimeFormat::kRgba8, VK_FORMAT_R8G8B8A8_UNORM},
      {RuntimeFormat::kR8, VK_FORMAT_R8_UNORM},
      {RuntimeFormat::kRg8, VK_FORMAT_R8G8_UNORM},
      {RuntimeFormat::kBc1, VK_FORMAT_BC1_RGB_UNORM_BLOCK},
      {RuntimeFormat::kBc3, VK_FORMAT_BC3_UNORM_BLOCK},
      {RuntimeFormat::kBc4, VK_FORMAT_BC4_UNORM_BLOCK},
      {RuntimeFormat::kBc5, VK_FORMAT_BC5_UNORM_BLOCK},
      {RuntimeFormat::kBc7, VK_FORMAT_BC7_UNORM_BLOCK},
      {RuntimeFormat::kRgba16f, VK_FORMAT_R16G16B16A16_SFLOAT},
      {RuntimeFormat::kBc6hUf16, VK_FORMAT_BC6H_UFLOAT_BLOCK},
      {RuntimeFormat::kBc6hSf16, VK_FORMAT_BC6H_SFLOAT_BLOCK}};
  for (const auto& [runtime, vk] : kFormats) {
    if (runtime == f) return vk;
  }
  return VK_FORMAT_UNDEFINED;
}

size_t cache_page_bytes(RuntimeFormat f, uint32_t page_size) {
  if (cache_vk_format(f) == VK_FORMAT_UNDEFINED) return 0;
  return runtime_format_page_bytes(f, page_size);
}

struct Renderer::Impl {
  explicit Impl(VulkanContext& c) : ctx(c) {}
  ~Impl();

  VulkanContext& ctx;
  VkDevice dev = VK_NULL_HANDLE;
  VkSampler trilinear_clamp = VK_NULL_HANDLE;
  VkSampler trilinear_repeat = VK_NULL_HANDLE;
  VkSampler cache_sampler = VK_NULL_HANDLE;
  VkSampler table_sampler = VK_NULL_HANDLE;
  VkDescriptorSetLayout ref_set_layout = VK_NULL_HANDLE;
  VkDescriptorSetLayout vt_set_layout = VK_NULL_HANDLE;
  VkPipelineLayout ref_layout = VK_NULL_HANDLE;
  VkPipelineLayout vt_layout = VK_NULL_HANDLE;
  VkPipeline ref_pipe = VK_NULL_HANDLE;
  VkPipeline fb_pipe = VK_NULL_HANDLE;
  VkPipeline vt_pipe = VK_NULL_HANDLE;
  VkDescriptorPool ref_pool = VK_NULL_HANDLE;
  VkDescriptorPool vt_pool = VK_NULL_HANDLE;

  Image color, status, depth, fb, fb_depth;
  Buffer color_rb, status_rb, depth_rb, fb_rb;

  struct GpuMesh {
    Buffer vertices, indices;
    uint32_t index_count = 0;
    uint32_t texture = 0;
    float alpha_cutoff = -1.0f;
  };
  std::vector<GpuMesh> meshes;
  std::vector<GpuMesh> ref_meshes;
  bool separate_reference = false;
  const std::vector<GpuMesh>& reference_meshes() const {
    return separate_reference ? ref_meshes : meshes;
  }
  Status upload_meshes(std::span<const MeshData> meshes, std::vector<GpuMesh>& out);

  struct GpuTexture {
    Image image;
    VkDescriptorSet set = VK_NULL_HANDLE;
    uint32_t width = 0, height = 0, max_level = 0;
    uint32_t levels_width = 0, levels_height = 0;  // ReferenceTexture's
    AddressMode mode = AddressMode::kClamp;
    bool sampler_addressing = false;     // a material sampler addresses the taps
    VkSampler sampler = VK_NULL_HANDLE;  // reference_sampler(); owned by Impl
  };
  std::vector<GpuTexture> textures;
  // Material samplers (trilinear, per-axis addressing, magFilter), made once per distinct kind.
  std::vector<std::pair<uint32_t, VkSampler>> material_samplers;
  Expected<VkSampler> material_sampler(const TextureSampler& sampler);
  // Copies pages in `format` into their slots of a physical cache (`what` names them in errors).
  Status upload_pages(Image& cache, RuntimeFormat format, std::span<const SlotUpload> pages,
                      const char* what);
  Expected<VkSampler> reference_sampler(const ReferenceTexture& tex);

  bool has_vt = false;
  VirtualTextureSetup vt;
  Image cache, table;
  VkDescriptorSet vt_set = VK_NULL_HANDLE;

  Status init(const RenderOptions& o);
  Expected<VkPipeline> make_pipeline(VkPipelineLayout layout, std::span<const uint32_t> fs,
                                     std::span<const VkFormat> color_formats);
  Expected<VkSampler> make_sampler(VkFilter filter, VkSamplerMipmapMode mip,
                                   VkSamplerAddressMode address);
  Expected<Image> make_target(uint32_t w, uint32_t h, VkFormat f, bool depth_target);
  void begin_pass(VkCommandBuffer cmd, std::span<const Image* const> targets, const Image& depth,
                  uint32_t w, uint32_t h, std::span<const VkClearColorValue> clears);
  // `depth_readback` (may be null) receives the depth target.
  void end_pass(VkCommandBuffer cmd, std::span<const Image* const> targets,
                std::span<const Buffer* const> readbacks, const Image& depth,
                const Buffer* depth_readback, uint32_t w, uint32_t h);

  // One render pass: clear the targets, bind `pipe`, draw, copy each target to its readback.
  struct PassTargets {
    std::span<const Image* const> targets;
    std::span<const Buffer* const> readbacks;
    const Image* depth;
    uint32_t width, height;
    std::span<const VkClearColorValue> clears;
    const Buffer* depth_readback = nullptr;
  };
  Status run_pass(const PassTargets& pass, VkPipeline pipe,
                  const std::function<void(VkCommandBuffer)>& draw);
  // The reference and virtual passes share the colour and status targets; `read_depth` (the
  // reference passes: compare_view's silhouettes) also copies the depth target to depth_rb.
  Status run_color_pass(uint32_t w, uint32_t h, VkPipeline pipe, bool read_depth,
                        const std::function<void(VkCommandBuffer)>& draw);
  Rgba8Image read_color(uint32_t w, uint32_t h) const;
  std::vector<float> read_view_depth(const Camera& camera, uint32_t w, uint32_t h) const;

  // Stages `bytes` and copies them into `image`, which is in `from` before and shader-readable
  // after.
  Status upload_image(Image& image, std::span<const uint8_t> bytes,
                      std::span<const ImageCopy> copies, VkImageLayout from);
  // A pool of `sets` descriptor sets of `descriptors` combined image samplers in all.
  Expected<VkDescriptorPool> make_pool(uint32_t sets, uint32_t descriptors);
  Expected<VkDescriptorSet> allocate_set(VkDescriptorPool pool, VkDescriptorSetLayout layout);

  // Lit passes (after the other members: destroyed first).
  LitState lit;
  Status init_lit();
  Expected<Image> upload_texture(const ReferenceTexture& tex, const std::string& name);
};

Renderer::Impl::~Impl() {
  if (!dev) return;
  vkDeviceWaitIdle(dev);
  for (VkPipeline p : {ref_pipe, fb_pipe, vt_pipe}) {
    if (p) vkDestroyPipeline(dev, p, nullptr);
  }
  for (VkPipelineLayout l : {ref_layout, vt_layout}) {
    if (l) vkDestroyPipelineLayout(dev, l, nullptr);
  }
  for (VkDescriptorSetLayout l : {ref_set_layout, vt_set_layout}) {
    if (l) vkDestroyDescriptorSetLayout(dev, l, nullptr);
  }
  for (VkDescriptorPool p : {ref_pool, vt_pool}) {
    if (p) vkDestroyDescriptorPool(dev, p, nullptr);
  }
  for (VkSampler s : {trilinear_clamp, trilinear_repeat, cache_sampler, table_sampler}) {
    if (s) vkDestroySampler(dev, s, nullptr);
  }
  for (const auto& [kind, s] : material_samplers) vkDestroySampler(dev, s, nullptr);
}

namespace {

VkSamplerAddressMode vk_address(scene::WrapMode m) {
  switch (m) {
    case scene::WrapMode::kClampToEdge:
      return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    case scene::WrapMode::kMirroredRepeat:
      return VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT;
    case scene::WrapMode::kRepeat:
      break;
  }
  return VK_SAMPLER_ADDRESS_MODE_REPEAT;
}

}  // namespace

Expected<VkSampler> Renderer::Impl::material_sampler(const TextureSampler& m) {
  const uint32_t kind = uint32_t(m.wrap_s) | uint32_t(m.wrap_t) << 4 | uint32_t(m.mag_filter) << 8;
  for (const auto& [k, s] : material_samplers) {
    if (k == kind) return s;
  }
  VkSamplerCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  ci.magFilter = m.mag_filter == scene::FilterMode::kNearest ? VK_FILTER_NEAREST : VK_FILTER_LINEAR;
  ci.minFilter = VK_FILTER_LINEAR;
  ci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
  ci.addressModeU = vk_address(m.wrap_s);
  ci.addressModeV = vk_address(m.wrap_t);
  ci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  ci.maxLod = VK_LOD_CLAMP_NONE;
  VkSampler s;
  VT_VK(vkCreateSampler(dev, &ci, nullptr, &s));
  material_samplers.emplace_back(kind, s);
  return s;
}

Status Renderer::Impl::upload_pages(Image& cache, RuntimeFormat format,
                                    std::span<const SlotUpload> pages, const char* what) {
  const uint32_t ps = vt.geometry.page_size();
  const size_t bytes = cache_page_bytes(format, ps);
  std::vector<uint8_t> staging;
  staging.reserve(bytes * pages.size());
  std::vector<ImageCopy> copies;
  for (const SlotUpload& p : pages) {
    if (p.slot_x >= vt.slots_x || p.slot_y >= vt.slots_y || p.bytes.size() != bytes) {
      return Error(ErrorCode::kInvalidArgument,
                   std::string("render: ") + what + " upload to slot (" + std::to_string(p.slot_x) +
                       ", " + std::to_string(p.slot_y) + ") has a bad slot or " +
                       std::to_string(p.bytes.size()) + " bytes instead of " +
                       std::to_string(bytes));
    }
    copies.push_back({staging.size(), 0, int32_t(p.slot_x * ps), int32_t(p.slot_y * ps), ps, ps});
    staging.insert(staging.end(), p.bytes.begin(), p.bytes.end());
  }
  return upload_image(cache, staging, copies, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

Expected<VkSampler> Renderer::Impl::reference_sampler(const ReferenceTexture& tex) {
  if (tex.sampler) return material_sampler(*tex.sampler);
  if (tex.levels_width) return trilinear_repeat;  // the padding addresses the edges
  return tex.address_mode == AddressMode::kWrap ? trilinear_repeat : trilinear_clamp;
}

Expected<VkSampler> Renderer::Impl::make_sampler(VkFilter filter, VkSamplerMipmapMode mip,
                                                 VkSamplerAddressMode address) {
  VkSamplerCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  ci.magFilter = ci.minFilter = filter;
  ci.mipmapMode = mip;
  ci.addressModeU = ci.addressModeV = ci.addressModeW = address;
  ci.maxLod = VK_LOD_CLAMP_NONE;
  VkSampler s;
  VT_VK(vkCreateSampler(dev, &ci, nullptr, &s));
  return s;
}

Expected<Image> Renderer::Impl::make_target(uint32_t w, uint32_t h, VkFormat f, bool depth_target) {
  ImageDesc d;
  d.width = w;
  d.height = h;
  d.format = f;
  d.usage = (depth_target ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT
                          : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) |
            VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  d.aspect = depth_target ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  return ctx.create_image(d);
}

Expected<VkPipeline> Renderer::Impl::make_pipeline(VkPipelineLayout layout,
                                                   std::span<const uint32_t> fs,
                                                   std::span<const VkFormat> color_formats) {
  auto module = [&](std::span<const uint32_t> code) -> Expected<VkShaderModule> {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = code.size_bytes();
    ci.pCode = code.data();
    VkShaderModule m;
    VT_VK(vkCreateShaderModule(dev, &ci, nullptr, &m));
    return m;
  };
  VT_ASSIGN_OR_RETURN(VkShaderModule vs, module(spirv_mesh_vert()));
  auto fs_module = module(fs);
  if (!fs_module.ok()) {
    vkDestroyShaderModule(dev, vs, nullptr);
    return fs_module.status();
  }
  VkPipelineShaderStageCreateInfo stages[2] = {
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vs;
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = *fs_module;
  stages[1].pName = "main";

  VkVertexInputBindingDescription binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
  VkVertexInputAttributeDescription attrs[7] = {
      {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, x)},
      {1, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, u)},
      {2, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(Vertex, r)},
      {3, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, nx)},
      {4, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(Vertex, tx)},
      {5, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(Vertex, tex_uv[0])},
      {6, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(Vertex, tex_uv[2])}};
  VkPipelineVertexInputStateCreateInfo vi{
      VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = 1;
  vi.pVertexBindingDescriptions = &binding;
  vi.vertexAttributeDescriptionCount = uint32_t(std::size(attrs));
  vi.pVertexAttributeDescriptions = attrs;
  VkPipelineInputAssemblyStateCreateInfo ia{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = 1;
  vp.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo rs{
      VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE;  // unwrapped scenes may have open or two-sided surfaces
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{
      VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS;
  std::vector<VkPipelineColorBlendAttachmentState> blends(color_formats.size());
  for (auto& b : blends) b.colorWriteMask = 0xF;
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = uint32_t(blends.size());
  cb.pAttachments = blends.data();
  VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dy{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dy.dynamicStateCount = 2;
  dy.pDynamicStates = dyn;
  VkPipelineRenderingCreateInfo ri{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  ri.colorAttachmentCount = uint32_t(color_formats.size());
  ri.pColorAttachmentFormats = color_formats.data();
  ri.depthAttachmentFormat = kDepthFormat;

  VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  ci.pNext = &ri;
  ci.stageCount = 2;
  ci.pStages = stages;
  ci.pVertexInputState = &vi;
  ci.pInputAssemblyState = &ia;
  ci.pViewportState = &vp;
  ci.pRasterizationState = &rs;
  ci.pMultisampleState = &ms;
  ci.pDepthStencilState = &ds;
  ci.pColorBlendState = &cb;
  ci.pDynamicState = &dy;
  ci.layout = layout;
  VkPipeline pipe = VK_NULL_HANDLE;
  VkResult r = vkCreateGraphicsPipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &pipe);
  vkDestroyShaderModule(dev, vs, nullptr);
  vkDestroyShaderModule(dev, *fs_module, nullptr);
  VT_VK(r);
  return pipe;
}

Status Renderer::Impl::init(const RenderOptions& o) {
  dev = ctx.device();
  VT_ASSIGN_OR_RETURN(trilinear_clamp, make_sampler(VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR,
                                                    VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE));
  VT_ASSIGN_OR_RETURN(trilinear_repeat,
                      make_sampler(VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR,
                                   VK_SAMPLER_ADDRESS_MODE_REPEAT));
  VT_ASSIGN_OR_RETURN(cache_sampler, make_sampler(VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST,
                                                  VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE));
  VT_ASSIGN_OR_RETURN(table_sampler, make_sampler(VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST,
                                                  VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE));

  VkDescriptorSetLayoutBinding bindings[2] = {};
  for (uint32_t i = 0; i < 2; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
  }
  VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  sl.bindingCount = 1;
  sl.pBindings = bindings;
  VT_VK(vkCreateDescriptorSetLayout(dev, &sl, nullptr, &ref_set_layout));
  sl.bindingCount = 2;
  VT_VK(vkCreateDescriptorSetLayout(dev, &sl, nullptr, &vt_set_layout));

  VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                           sizeof(Push)};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &push;
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &ref_set_layout;
  VT_VK(vkCreatePipelineLayout(dev, &pl, nullptr, &ref_layout));
  pl.pSetLayouts = &vt_set_layout;
  VT_VK(vkCreatePipelineLayout(dev, &pl, nullptr, &vt_layout));

  const VkFormat ref_formats[] = {kColorFormat, kUintFormat};
  const VkFormat fb_formats[] = {kUintFormat};
  const VkFormat vt_formats[] = {kColorFormat, kUintFormat};
  VT_ASSIGN_OR_RETURN(ref_pipe, make_pipeline(ref_layout, spirv_reference_frag(), ref_formats));
  VT_ASSIGN_OR_RETURN(fb_pipe, make_pipeline(vt_layout, spirv_feedback_frag(), fb_formats));
  VT_ASSIGN_OR_RETURN(vt_pipe, make_pipeline(vt_layout, spirv_virtual_frag(), vt_formats));

  uint32_t fw = std::max(1u, o.width / o.feedback_divisor);
  uint32_t fh = std::max(1u, o.height / o.feedback_divisor);
  VT_ASSIGN_OR_RETURN(color, make_target(o.width, o.height, kColorFormat, false));
  VT_ASSIGN_OR_RETURN(status, make_target(o.width, o.height, kUintFormat, false));
  VT_ASSIGN_OR_RETURN(depth, make_target(o.width, o.height, kDepthFormat, true));
  VT_ASSIGN_OR_RETURN(fb, make_target(fw, fh, kUintFormat, false));
  VT_ASSIGN_OR_RETURN(fb_depth, make_target(fw, fh, kDepthFormat, true));
  const VkDeviceSize full = VkDeviceSize(o.width) * o.height * 4;
  VT_ASSIGN_OR_RETURN(color_rb, ctx.create_buffer(full, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true));
  VT_ASSIGN_OR_RETURN(status_rb, ctx.create_buffer(full, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true));
  VT_ASSIGN_OR_RETURN(depth_rb, ctx.create_buffer(full, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true));
  VT_ASSIGN_OR_RETURN(
      fb_rb, ctx.create_buffer(VkDeviceSize(fw) * fh * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true));
  return Status::Ok();
}

void Renderer::Impl::begin_pass(VkCommandBuffer cmd, std::span<const Image* const> targets,
                                const Image& depth_image, uint32_t w, uint32_t h,
                                std::span<const VkClearColorValue> clears) {
  std::vector<VkRenderingAttachmentInfo> atts;
  for (size_t i = 0; i < targets.size(); ++i) {
    VulkanContext::transition(cmd, *targets[i], VK_IMAGE_LAYOUT_UNDEFINED,
                              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    VkRenderingAttachmentInfo a{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    a.imageView = targets[i]->view();
    a.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    a.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    a.clearValue.color = clears[i];
    atts.push_back(a);
  }
  VulkanContext::transition(cmd, depth_image, VK_IMAGE_LAYOUT_UNDEFINED,
                            VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
  VkRenderingAttachmentInfo da{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  da.imageView = depth_image.view();
  da.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  da.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  da.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  da.clearValue.depthStencil = {1.0f, 0};
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, {w, h}};
  ri.layerCount = 1;
  ri.colorAttachmentCount = uint32_t(atts.size());
  ri.pColorAttachments = atts.data();
  ri.pDepthAttachment = &da;
  vkCmdBeginRendering(cmd, &ri);
  VkViewport viewport{0, 0, float(w), float(h), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, {w, h}};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void Renderer::Impl::end_pass(VkCommandBuffer cmd, std::span<const Image* const> targets,
                              std::span<const Buffer* const> readbacks, const Image& depth_image,
                              const Buffer* depth_readback, uint32_t w, uint32_t h) {
  vkCmdEndRendering(cmd);
  if (depth_readback != nullptr) {
    VulkanContext::transition(cmd, depth_image, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                              VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    VkBufferImageCopy c{};
    c.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    c.imageExtent = {w, h, 1};
    vkCmdCopyImageToBuffer(cmd, depth_image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           depth_readback->handle(), 1, &c);
  }
  for (size_t i = 0; i < targets.size(); ++i) {
    VulkanContext::transition(cmd, *targets[i], VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                              VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    VkBufferImageCopy c{};
    c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    c.imageExtent = {w, h, 1};
    vkCmdCopyImageToBuffer(cmd, targets[i]->handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           readbacks[i]->handle(), 1, &c);
  }
  VkMemoryBarrier2 mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  mb.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
  mb.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  mb.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
  mb.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.memoryBarrierCount = 1;
  dep.pMemoryBarriers = &mb;
  vkCmdPipelineBarrier2(cmd, &dep);
}

Status Renderer::Impl::upload_image(Image& image, std::span<const uint8_t> bytes,
                                    std::span<const ImageCopy> copies, VkImageLayout from) {
  VT_ASSIGN_OR_RETURN(Buffer buf, ctx.create_buffer_with(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT));
  return ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    VulkanContext::transition(cmd, image, from, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    VulkanContext::copy_buffer_to_image(cmd, buf, image, copies);
    VulkanContext::transition(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  });
}

Expected<VkDescriptorPool> Renderer::Impl::make_pool(uint32_t sets, uint32_t descriptors) {
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, descriptors};
  VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pci.maxSets = sets;
  pci.poolSizeCount = 1;
  pci.pPoolSizes = &size;
  VkDescriptorPool pool;
  VT_VK(vkCreateDescriptorPool(dev, &pci, nullptr, &pool));
  return pool;
}

Expected<VkDescriptorSet> Renderer::Impl::allocate_set(VkDescriptorPool pool,
                                                       VkDescriptorSetLayout layout) {
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &layout;
  VkDescriptorSet set;
  VT_VK(vkAllocateDescriptorSets(dev, &ai, &set));
  return set;
}

Renderer::Renderer(std::unique_ptr<Impl> impl, const RenderOptions& options)
    : impl_(std::move(impl)), options_(options) {}
Renderer::~Renderer() = default;

Expected<std::unique_ptr<Renderer>> Renderer::create(VulkanContext& ctx,
                                                     const RenderOptions& options) {
  if (options.width == 0 || options.height == 0 || options.width > 16384 ||
      options.height > 16384 || options.feedback_divisor == 0) {
    return Error(ErrorCode::kInvalidArgument,
                 "render: size " + std::to_string(options.width) + "x" +
                     std::to_string(options.height) + " / feedback divisor " +
                     std::to_string(options.feedback_divisor) + " is out of range");
  }
  auto impl = std::make_unique<Impl>(ctx);
  VT_RETURN_IF_ERROR(impl->init(options));
  return std::unique_ptr<Renderer>(new Renderer(std::move(impl), options));
}

uint32_t Renderer::feedback_width() const {
  return impl_->fb.desc().width;
}
uint32_t Renderer::feedback_height() const {
  return impl_->fb.desc().height;
}

Status Renderer::set_meshes(std::span<const MeshData> meshes) {
  return impl_->upload_meshes(meshes, impl_->meshes);
}

Status Renderer::set_reference_meshes(std::span<const MeshData> meshes) {
  impl_->separate_reference = true;
  return impl_->upload_meshes(meshes, impl_->ref_meshes);
}

Status Renderer::Impl::upload_meshes(std::span<const MeshData> meshes, std::vector<GpuMesh>& out) {
  std::vector<GpuMesh> gpu;
  for (size_t i = 0; i < meshes.size(); ++i) {
    const MeshData& m = meshes[i];
    if (m.indices.size() % 3 != 0) {
      return Error(ErrorCode::kInvalidArgument,
                   "render: mesh " + std::to_string(i) + " index count is not a multiple of 3");
    }
    for (uint32_t idx : m.indices) {
      if (idx >= m.vertices.size()) {
        return Error(ErrorCode::kInvalidArgument,
                     "render: mesh " + std::to_string(i) + " has an index past its vertices");
      }
    }
    if (m.indices.empty()) continue;
    GpuMesh g;
    std::span<const uint8_t> vb(reinterpret_cast<const uint8_t*>(m.vertices.data()),
                                m.vertices.size() * sizeof(Vertex));
    std::span<const uint8_t> ib(reinterpret_cast<const uint8_t*>(m.indices.data()),
                                m.indices.size() * sizeof(uint32_t));
    VT_ASSIGN_OR_RETURN(g.vertices, ctx.create_buffer_with(vb, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT));
    VT_ASSIGN_OR_RETURN(g.indices, ctx.create_buffer_with(ib, VK_BUFFER_USAGE_INDEX_BUFFER_BIT));
    g.index_count = uint32_t(m.indices.size());
    g.texture = m.reference_texture;
    g.alpha_cutoff = m.alpha_cutoff;
    gpu.push_back(std::move(g));
  }
  vkDeviceWaitIdle(dev);
  out = std::move(gpu);
  return Status::Ok();
}

Status Renderer::set_reference_textures(std::span<const ReferenceTexture> textures) {
  Impl& s = *impl_;
  vkDeviceWaitIdle(s.dev);
  s.textures.clear();
  if (s.ref_pool) vkDestroyDescriptorPool(s.dev, s.ref_pool, nullptr);
  s.ref_pool = VK_NULL_HANDLE;
  if (textures.empty()) return Status::Ok();

  const uint32_t count = uint32_t(textures.size());
  VT_ASSIGN_OR_RETURN(s.ref_pool, s.make_pool(count, count));

  for (size_t t = 0; t < textures.size(); ++t) {
    const ReferenceTexture& tex = textures[t];
    const std::string name = "render: reference texture " + std::to_string(t);
    if (tex.width == 0 || tex.height == 0 || tex.levels.empty()) {
      return Error(ErrorCode::kInvalidArgument, name + " is empty");
    }
    uint32_t levels =
        std::min<uint32_t>(uint32_t(tex.levels.size()), mip_count(tex.width, tex.height));
    std::vector<ImageCopy> copies;
    std::vector<uint8_t> staging;
    for (uint32_t l = 0; l < levels; ++l) {
      uint32_t w = std::max(1u, tex.width >> l), h = std::max(1u, tex.height >> l);
      if (tex.levels[l].size() != size_t(w) * h * 4) {
        return Error(ErrorCode::kInvalidArgument,
                     name + " level " + std::to_string(l) + " has the wrong byte count");
      }
      copies.push_back({staging.size(), l, 0, 0, w, h});
      staging.insert(staging.end(), tex.levels[l].begin(), tex.levels[l].end());
    }
    Impl::GpuTexture g;
    g.width = tex.width;
    g.height = tex.height;
    g.max_level = std::min(levels - 1, tex.max_level);
    g.levels_width = tex.levels_width;
    g.levels_height = tex.levels_height;
    g.mode = tex.address_mode;
    g.sampler_addressing = tex.sampler.has_value();
    VT_ASSIGN_OR_RETURN(VkSampler sampler, s.reference_sampler(tex));
    g.sampler = sampler;
    ImageDesc d;
    d.width = tex.width;
    d.height = tex.height;
    d.mip_levels = levels;
    VT_ASSIGN_OR_RETURN(g.image, s.ctx.create_image(d));
    VT_RETURN_IF_ERROR(s.upload_image(g.image, staging, copies, VK_IMAGE_LAYOUT_UNDEFINED));
    VT_ASSIGN_OR_RETURN(g.set, s.allocate_set(s.ref_pool, s.ref_set_layout));
    VkDescriptorImageInfo ii{sampler, g.image.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = g.set;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(s.dev, 1, &w, 0, nullptr);
    s.textures.push_back(std::move(g));
  }
  return Status::Ok();
}

Status Renderer::set_virtual_texture(const VirtualTextureSetup& setup) {
  Impl& s = *impl_;
  VT_RETURN_IF_ERROR(setup.geometry.validate().with_context("render: virtual texture"));
  const PageGeometry& g = setup.geometry;
  const uint32_t ps = g.page_size();
  if (setup.slots_x == 0 || setup.slots_y == 0 || setup.slots_x > 256 || setup.slots_y > 256 ||
      uint64_t(setup.slots_x) * ps > 16384 || uint64_t(setup.slots_y) * ps > 16384) {
    return Error(ErrorCode::kInvalidArgument,
                 "render: a physical cache of " + std::to_string(setup.slots_x) + "x" +
                     std::to_string(setup.slots_y) + " slots of " + std::to_string(ps) +
                     " texels exceeds 16384 texels or 256 slots per side");
  }
  // Page coordinates are 12 bits in the feedback format, levels 5 bits.
  if (g.pages_x(0) > 4096 || g.pages_y(0) > 4096 || g.level_count() > 31) {
    return Error(ErrorCode::kUnsupported,
                 "render: more than 4096 pages per side do not fit the feedback format");
  }
  const VkFormat cache_format = cache_vk_format(setup.cache_format);
  if (cache_format == VK_FORMAT_UNDEFINED || !s.ctx.supports_sampled_linear(cache_format)) {
    return Error(ErrorCode::kUnsupported, std::string("render: cannot sample a ") +
                                              to_string(setup.cache_format) +
                                              " physical cache with linear filtering");
  }
  vkDeviceWaitIdle(s.dev);
  s.has_vt = false;
  if (s.vt_pool) vkDestroyDescriptorPool(s.dev, s.vt_pool, nullptr);
  s.vt_pool = VK_NULL_HANDLE;

  ImageDesc cd;
  cd.width = setup.slots_x * ps;
  cd.height = setup.slots_y * ps;
  cd.format = cache_format;
  VT_ASSIGN_OR_RETURN(s.cache, s.ctx.create_image(cd));
  // Vulkan mips halve with floor but page grids halve with ceil: a power-of-two base keeps every
  // level's grid inside its mip (ceil(n / 2^L) <= next_pow2(n) / 2^L).
  ImageDesc td;
  td.width = next_pow2(g.pages_x(0));
  td.height = next_pow2(g.pages_y(0));
  td.mip_levels = mip_count(td.width, td.height);
  td.format = kPageTableFormat;
  if (td.mip_levels < g.level_count()) {
    return Error(ErrorCode::kInternal, "render: page-table mip chain shorter than the levels");
  }
  VT_ASSIGN_OR_RETURN(s.table, s.ctx.create_image(td));
  // Zero the table (no page valid) so a frame before the first upload reads defined data.
  std::vector<uint8_t> zeros(size_t(td.width) * td.height * 4, 0);
  VT_RETURN_IF_ERROR(s.ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    VulkanContext::transition(cmd, s.cache, VK_IMAGE_LAYOUT_UNDEFINED,
                              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  }));
  std::vector<ImageCopy> copies;
  for (uint32_t l = 0; l < td.mip_levels; ++l) {
    copies.push_back({0, l, 0, 0, std::max(1u, td.width >> l), std::max(1u, td.height >> l)});
  }
  VT_RETURN_IF_ERROR(s.upload_image(s.table, zeros, copies, VK_IMAGE_LAYOUT_UNDEFINED));

  VT_ASSIGN_OR_RETURN(s.vt_pool, s.make_pool(1, 2));
  VT_ASSIGN_OR_RETURN(s.vt_set, s.allocate_set(s.vt_pool, s.vt_set_layout));
  VkDescriptorImageInfo infos[2] = {
      {s.cache_sampler, s.cache.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
      {s.table_sampler, s.table.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}};
  VkWriteDescriptorSet w[2] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET},
                               {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
  for (uint32_t i = 0; i < 2; ++i) {
    w[i].dstSet = s.vt_set;
    w[i].dstBinding = i;
    w[i].descriptorCount = 1;
    w[i].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w[i].pImageInfo = &infos[i];
  }
  vkUpdateDescriptorSets(s.dev, 2, w, 0, nullptr);
  s.vt = setup;
  s.has_vt = true;
  return Status::Ok();
}

Status Renderer::upload_slots(std::span<const SlotUpload> pages) {
  Impl& s = *impl_;
  if (!s.has_vt) return Error(ErrorCode::kInvalidArgument, "render: no virtual texture set");
  if (pages.empty()) return Status::Ok();
  return s.upload_pages(s.cache, s.vt.cache_format, pages, "page");
}

Status Renderer::upload_page_table(const PageTableLevels& table) {
  Impl& s = *impl_;
  if (!s.has_vt) return Error(ErrorCode::kInvalidArgument, "render: no virtual texture set");
  const PageGeometry& g = s.vt.geometry;
  if (table.levels.size() != g.level_count()) {
    return Error(ErrorCode::kInvalidArgument,
                 "render: page table has " + std::to_string(table.levels.size()) +
                     " levels, the geometry " + std::to_string(g.level_count()));
  }
  std::vector<uint8_t> staging;
  std::vector<ImageCopy> copies;
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    if (table.levels[l].size() != g.pages_in_level(l) * 4) {
      return Error(ErrorCode::kInvalidArgument,
                   "render: page table level " + std::to_string(l) + " has the wrong size");
    }
    copies.push_back({staging.size(), l, 0, 0, g.pages_x(l), g.pages_y(l)});
    staging.insert(staging.end(), table.levels[l].begin(), table.levels[l].end());
  }
  return s.upload_image(s.table, staging, copies, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

namespace {

// Pushes the constants of one mesh and draws it.
template <typename Mesh>
void draw_mesh(VkCommandBuffer cmd, VkPipelineLayout layout, const Push& p, const Mesh& m) {
  vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                     sizeof(p), &p);
  VkDeviceSize offset = 0;
  VkBuffer vb = m.vertices.handle();
  vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &offset);
  vkCmdBindIndexBuffer(cmd, m.indices.handle(), 0, VK_INDEX_TYPE_UINT32);
  vkCmdDrawIndexed(cmd, m.index_count, 1, 0, 0, 0);
}

}  // namespace

namespace {

std::vector<uint32_t> read_u32(const Buffer& readback, size_t count) {
  std::vector<uint32_t> out(count);
  std::memcpy(out.data(), readback.mapped(), count * 4);
  return out;
}

// Fills the virtual-texture fields of the push constants.
void fill_vt_push(Push& p, const VirtualTextureSetup& vt) {
  const PageGeometry& g = vt.geometry;
  p.tex[0] = float(g.width);
  p.tex[1] = float(g.height);
  p.vt[0] = int32_t(g.level_count());
  p.vt[1] = int32_t(g.payload);
  p.vt[2] = int32_t(g.border);
  p.vt[3] = int32_t(g.page_size());
  p.misc[1] = vt.address_mode == AddressMode::kWrap ? 1 : 0;
  p.misc[2] = int32_t(g.level_count()) - 1;
  p.misc[3] = vt.tone_map ? 1 : 0;  // the lit passes put their inputs here instead
}

}  // namespace

Status Renderer::Impl::run_pass(const PassTargets& pass, VkPipeline pipe,
                                const std::function<void(VkCommandBuffer)>& draw) {
  return ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    begin_pass(cmd, pass.targets, *pass.depth, pass.width, pass.height, pass.clears);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
    draw(cmd);
    end_pass(cmd, pass.targets, pass.readbacks, *pass.depth, pass.depth_readback, pass.width,
             pass.height);
  });
}

Status Renderer::Impl::run_color_pass(uint32_t w, uint32_t h, VkPipeline pipe, bool read_depth,
                                      const std::function<void(VkCommandBuffer)>& draw) {
  const Image* targets[] = {&color, &status};
  const Buffer* readbacks[] = {&color_rb, &status_rb};
  const VkClearColorValue clears[] = {{{0.0f, 0.0f, 0.0f, 0.0f}}, {}};
  return run_pass({targets, readbacks, &depth, w, h, clears, read_depth ? &depth_rb : nullptr},
                  pipe, draw);
}

Rgba8Image Renderer::Impl::read_color(uint32_t w, uint32_t h) const {
  Rgba8Image out;
  out.width = w;
  out.height = h;
  out.texels.assign(color_rb.mapped(), color_rb.mapped() + size_t(w) * h * 4);
  return out;
}

std::vector<float> Renderer::Impl::read_view_depth(const Camera& camera, uint32_t w,
                                                   uint32_t h) const {
  // A perspective view_proj's depth row is -a times its w row plus b (w: distance along the view
  // axis), so window depth d = z / w = -a + b / w and w = b / (d + a); both recovered from the
  // matrix, so every camera (planned, file, jittered) is read alike.
  const auto& m = camera.view_proj.m;
  float ww = 0, zw = 0;
  for (int c = 0; c < 3; ++c) {
    ww += m[c * 4 + 3] * m[c * 4 + 3];
    zw += m[c * 4 + 2] * m[c * 4 + 3];
  }
  const float a = ww > 0 ? -zw / ww : 0.0f;
  const float b = m[14] + a * m[15];
  std::vector<float> out(size_t(w) * h);
  std::memcpy(out.data(), depth_rb.mapped(), out.size() * 4);
  for (float& d : out) d = d >= 1.0f ? 0.0f : b / (d + a);
  return out;
}

Expected<ReferenceFrame> Renderer::render_reference(const Camera& camera) {
  Impl& s = *impl_;
  for (const auto& m : s.reference_meshes()) {
    if (m.texture >= s.textures.size()) {
      return Error(ErrorCode::kInvalidArgument, "render: a mesh names reference texture " +
                                                    std::to_string(m.texture) + " but only " +
                                                    std::to_string(s.textures.size()) + " are set");
    }
  }
  const uint32_t w = options_.width, h = options_.height;
  VT_RETURN_IF_ERROR(s.run_color_pass(w, h, s.ref_pipe, true, [&](VkCommandBuffer cmd) {
    for (const auto& m : s.reference_meshes()) {
      const auto& t = s.textures[m.texture];
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.ref_layout, 0, 1, &t.set, 0,
                              nullptr);
      Push p{};
      std::memcpy(p.mvp, camera.view_proj.m.data(), sizeof(p.mvp));
      const bool file_levels = t.levels_width != 0;
      p.tex[0] = float(file_levels ? t.levels_width : t.width);
      p.tex[1] = float(file_levels ? t.levels_height : t.height);
      p.tex[2] = 1.0f;
      p.tex[3] = m.alpha_cutoff;
      p.misc[1] = t.sampler_addressing ? 2 : t.mode == AddressMode::kWrap ? 1 : 0;
      p.misc[2] = int32_t(t.max_level);
      p.misc[3] = file_levels ? 1 : 0;
      draw_mesh(cmd, s.ref_layout, p, m);
    }
  }));
  ReferenceFrame out;
  out.color = s.read_color(w, h);
  out.covered = read_u32(s.status_rb, size_t(w) * h);
  out.depth = s.read_view_depth(camera, w, h);
  return out;
}

Expected<FeedbackImage> Renderer::render_feedback(const Camera& camera, uint32_t frame) {
  Impl& s = *impl_;
  if (!s.has_vt) return Error(ErrorCode::kInvalidArgument, "render: no virtual texture set");
  const uint32_t w = feedback_width(), h = feedback_height();
  // Four sub-pixel positions, one per frame, so that over a cycle the low-resolution pass
  // sees the footprints of every quarter of its pixels.
  static const float kJitter[4][2] = {
      {-0.25f, -0.25f}, {0.25f, 0.25f}, {0.25f, -0.25f}, {-0.25f, 0.25f}};
  Mat4 mvp = jitter(camera.view_proj, kJitter[frame & 3][0], kJitter[frame & 3][1], int(w), int(h));
  const Image* targets[] = {&s.fb};
  const Buffer* readbacks[] = {&s.fb_rb};
  VkClearColorValue clear{};
  clear.uint32[0] = 0xFFFFFFFFu;
  const VkClearColorValue clears[] = {clear};
  VT_RETURN_IF_ERROR(s.run_pass({targets, readbacks, &s.fb_depth, w, h, clears}, s.fb_pipe,
                                [&](VkCommandBuffer cmd) {
                                  // The alpha test reads the cache as the virtual pass does.
                                  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS,
                                                          s.vt_layout, 0, 1, &s.vt_set, 0, nullptr);
                                  for (const auto& m : s.meshes) {
                                    Push p{};
                                    std::memcpy(p.mvp, mvp.m.data(), sizeof(p.mvp));
                                    fill_vt_push(p, s.vt);
                                    p.tex[2] = float(w) / float(options_.width);
                                    p.tex[3] = m.alpha_cutoff;
                                    p.misc[0] = int32_t(frame & 3);
                                    draw_mesh(cmd, s.vt_layout, p, m);
                                  }
                                }));
  FeedbackImage out;
  out.width = w;
  out.height = h;
  out.requests = read_u32(s.fb_rb, size_t(w) * h);
  return out;
}

Expected<VirtualFrame> Renderer::render_virtual(const Camera& camera) {
  Impl& s = *impl_;
  if (!s.has_vt) return Error(ErrorCode::kInvalidArgument, "render: no virtual texture set");
  const uint32_t w = options_.width, h = options_.height;
  VT_RETURN_IF_ERROR(s.run_color_pass(w, h, s.vt_pipe, false, [&](VkCommandBuffer cmd) {
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.vt_layout, 0, 1, &s.vt_set, 0,
                            nullptr);
    for (const auto& m : s.meshes) {
      Push p{};
      std::memcpy(p.mvp, camera.view_proj.m.data(), sizeof(p.mvp));
      fill_vt_push(p, s.vt);
      p.tex[2] = 1.0f;
      p.tex[3] = m.alpha_cutoff;
      draw_mesh(cmd, s.vt_layout, p, m);
    }
  }));
  VirtualFrame out;
  out.color = s.read_color(w, h);
  out.status = read_u32(s.status_rb, size_t(w) * h);
  return out;
}

// ---- Lit passes ----

namespace {

// Mirrors `LitFrame` in shaders/lit.glsl (std140: three vec4).
struct LitFrameBlock {
  float eye[4];
  float key[4];
  float fill[4];
};

int32_t float_bits(float f) {
  int32_t i;
  std::memcpy(&i, &f, sizeof(i));
  return i;
}

void fill_lit_frame(const Buffer& frame, const LitFrameOptions& o) {
  LitFrameBlock b{};
  for (int c = 0; c < 3; ++c)
    b.eye[c] = o.eye[c], b.key[c] = o.key_dir[c], b.fill[c] = o.fill_dir[c];
  b.eye[3] = o.ambient;
  b.key[3] = o.key;
  b.fill[3] = o.fill;
  std::memcpy(frame.mapped(), &b, sizeof(b));
}

// The shader's frame bits (lit.glsl kLitNormal, kLitOrm, kLitEmissive, kLitNormalsFrame).
int32_t lit_frame_bits(const LitFrameOptions& o) {
  auto has = [&](LitInput i) { return (o.inputs >> uint32_t(i)) & 1u; };
  return int32_t(has(LitInput::kNormal) | has(LitInput::kOrm) << 1 | has(LitInput::kEmissive) << 2 |
                 uint32_t(o.shading_normals) << 3);
}

}  // namespace

Expected<Image> Renderer::Impl::upload_texture(const ReferenceTexture& tex,
                                               const std::string& name) {
  if (tex.width == 0 || tex.height == 0 || tex.levels.empty()) {
    return Error(ErrorCode::kInvalidArgument, name + " is empty");
  }
  const uint32_t levels =
      std::min<uint32_t>(uint32_t(tex.levels.size()), mip_count(tex.width, tex.height));
  std::vector<ImageCopy> copies;
  std::vector<uint8_t> staging;
  for (uint32_t l = 0; l < levels; ++l) {
    uint32_t w = std::max(1u, tex.width >> l), h = std::max(1u, tex.height >> l);
    if (tex.levels[l].size() != size_t(w) * h * 4) {
      return Error(ErrorCode::kInvalidArgument,
                   name + " level " + std::to_string(l) + " has the wrong byte count");
    }
    copies.push_back({staging.size(), l, 0, 0, w, h});
    staging.insert(staging.end(), tex.levels[l].begin(), tex.levels[l].end());
  }
  ImageDesc d;
  d.width = tex.width;
  d.height = tex.height;
  d.mip_levels = levels;
  VT_ASSIGN_OR_RETURN(Image image, ctx.create_image(d));
  VT_RETURN_IF_ERROR(upload_image(image, staging, copies, VK_IMAGE_LAYOUT_UNDEFINED));
  return image;
}

Status Renderer::Impl::init_lit() {
  if (lit.ready()) return Status::Ok();
  lit.dev = dev;
  // Reference: albedo, normal, metallic-roughness, emissive, occlusion, LitFrame. Virtual: page
  // table, the four caches, LitFrame.
  auto set_layout = [&](uint32_t samplers, VkDescriptorSetLayout* out) -> Status {
    std::vector<VkDescriptorSetLayoutBinding> b(samplers + 1);
    for (uint32_t i = 0; i <= samplers; ++i) {
      b[i].binding = i;
      b[i].descriptorType = i < samplers ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER
                                         : VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
      b[i].descriptorCount = 1;
      b[i].stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
    }
    VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    ci.bindingCount = uint32_t(b.size());
    ci.pBindings = b.data();
    VT_VK(vkCreateDescriptorSetLayout(dev, &ci, nullptr, out));
    return Status::Ok();
  };
  VT_RETURN_IF_ERROR(set_layout(5, &lit.ref_set_layout));
  VT_RETURN_IF_ERROR(set_layout(5, &lit.vt_set_layout));
  VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                           sizeof(Push)};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &push;
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &lit.ref_set_layout;
  VT_VK(vkCreatePipelineLayout(dev, &pl, nullptr, &lit.ref_layout));
  pl.pSetLayouts = &lit.vt_set_layout;
  VT_VK(vkCreatePipelineLayout(dev, &pl, nullptr, &lit.vt_layout));
  const VkFormat formats[] = {kColorFormat, kUintFormat};
  VT_ASSIGN_OR_RETURN(lit.vt_pipe, make_pipeline(lit.vt_layout, spirv_lit_virtual_frag(), formats));
  VT_ASSIGN_OR_RETURN(lit.frame, ctx.create_buffer(sizeof(LitFrameBlock),
                                                   VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true));
  ReferenceTexture white;
  white.width = white.height = 1;
  white.levels = {{255, 255, 255, 255}};
  VT_ASSIGN_OR_RETURN(lit.blank, upload_texture(white, "render: lit blank texture"));
  // Last: ready() means everything above exists.
  VT_ASSIGN_OR_RETURN(lit.ref_pipe,
                      make_pipeline(lit.ref_layout, spirv_lit_reference_frag(), formats));
  return Status::Ok();
}

namespace {

// A pool of `sets` sets with `samplers` combined image samplers and one uniform buffer each.
Expected<VkDescriptorPool> make_lit_pool(VkDevice dev, uint32_t sets, uint32_t samplers) {
  VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, sets * samplers},
                                   {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, sets}};
  VkDescriptorPoolCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  ci.maxSets = sets;
  ci.poolSizeCount = 2;
  ci.pPoolSizes = sizes;
  VkDescriptorPool pool;
  VT_VK(vkCreateDescriptorPool(dev, &ci, nullptr, &pool));
  return pool;
}

// Writes `images` to bindings 0.. of `set` and the lit frame buffer to the binding after them.
void write_lit_set(VkDevice dev, VkDescriptorSet set, std::span<const VkDescriptorImageInfo> images,
                   const Buffer& frame) {
  std::vector<VkWriteDescriptorSet> w(images.size() + 1, {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET});
  VkDescriptorBufferInfo bi{frame.handle(), 0, sizeof(LitFrameBlock)};
  for (uint32_t i = 0; i < w.size(); ++i) {
    w[i].dstSet = set;
    w[i].dstBinding = i;
    w[i].descriptorCount = 1;
    if (i < images.size()) {
      w[i].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
      w[i].pImageInfo = &images[i];
    } else {
      w[i].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
      w[i].pBufferInfo = &bi;
    }
  }
  vkUpdateDescriptorSets(dev, uint32_t(w.size()), w.data(), 0, nullptr);
}

}  // namespace

Status Renderer::set_lit_materials(std::span<const LitMaterial> materials) {
  Impl& s = *impl_;
  if (materials.size() != s.textures.size()) {
    return Error(ErrorCode::kInvalidArgument,
                 "render: " + std::to_string(materials.size()) + " lit materials for " +
                     std::to_string(s.textures.size()) + " reference textures");
  }
  VT_RETURN_IF_ERROR(s.init_lit());
  vkDeviceWaitIdle(s.dev);
  s.lit.materials.clear();
  if (s.lit.ref_pool) vkDestroyDescriptorPool(s.dev, s.lit.ref_pool, nullptr);
  s.lit.ref_pool = VK_NULL_HANDLE;
  if (materials.empty()) return Status::Ok();
  VT_ASSIGN_OR_RETURN(s.lit.ref_pool, make_lit_pool(s.dev, uint32_t(materials.size()), 5));
  for (size_t i = 0; i < materials.size(); ++i) {
    const LitMaterial& m = materials[i];
    const std::string name = "render: lit material " + std::to_string(i);
    LitState::Material g;
    VT_ASSIGN_OR_RETURN(g.normal, s.upload_texture(m.normal, name + " normal map"));
    VT_ASSIGN_OR_RETURN(g.orm, s.upload_texture(m.orm, name + " ORM"));
    VT_ASSIGN_OR_RETURN(g.emissive, s.upload_texture(m.emissive, name + " emissive"));
    VT_ASSIGN_OR_RETURN(g.occlusion, s.upload_texture(m.occlusion, name + " occlusion"));
    VT_ASSIGN_OR_RETURN(const VkSampler normal_sampler, s.reference_sampler(m.normal));
    VT_ASSIGN_OR_RETURN(const VkSampler orm_sampler, s.reference_sampler(m.orm));
    VT_ASSIGN_OR_RETURN(const VkSampler emissive_sampler, s.reference_sampler(m.emissive));
    VT_ASSIGN_OR_RETURN(const VkSampler occlusion_sampler, s.reference_sampler(m.occlusion));
    for (int c = 0; c < 3; ++c) g.emissive_scale[c] = m.emissive_scale[c];
    g.normal_scale = m.normal_scale;
    g.flags = (m.has_normal_map ? 1 : 0) | (m.two_channel_normal ? 2 : 0);
    VT_ASSIGN_OR_RETURN(g.set, s.allocate_set(s.lit.ref_pool, s.lit.ref_set_layout));
    const Impl::GpuTexture& albedo = s.textures[i];
    const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    const VkDescriptorImageInfo images[5] = {{albedo.sampler, albedo.image.view(), ro},
                                             {normal_sampler, g.normal.view(), ro},
                                             {orm_sampler, g.orm.view(), ro},
                                             {emissive_sampler, g.emissive.view(), ro},
                                             {occlusion_sampler, g.occlusion.view(), ro}};
    write_lit_set(s.dev, g.set, images, s.lit.frame);
    s.lit.materials.push_back(std::move(g));
  }
  return Status::Ok();
}

Status Renderer::set_lit_caches(
    std::span<const std::optional<RuntimeFormat>, kLitInputCount> formats) {
  Impl& s = *impl_;
  if (!s.has_vt) return Error(ErrorCode::kInvalidArgument, "render: no virtual texture set");
  // The albedo cache's size addresses every cache in the shader.
  if (!formats[0]) {
    return Error(ErrorCode::kInvalidArgument, "render: the lit caches need an albedo cache");
  }
  VT_RETURN_IF_ERROR(s.init_lit());
  vkDeviceWaitIdle(s.dev);
  const uint32_t ps = s.vt.geometry.page_size();
  for (uint32_t i = 0; i < kLitInputCount; ++i) {
    if (!formats[i]) {
      s.lit.caches[i].reset();
      s.lit.formats[i].reset();
      continue;
    }
    const VkFormat f = cache_vk_format(*formats[i]);
    if (f == VK_FORMAT_UNDEFINED || !s.ctx.supports_sampled_linear(f)) {
      return Error(ErrorCode::kUnsupported, std::string("render: cannot sample a ") +
                                                to_string(*formats[i]) +
                                                " lit cache with linear filtering");
    }
    const ImageDesc& have = s.lit.caches[i].desc();
    if (!s.lit.caches[i].handle() || s.lit.formats[i] != formats[i] ||
        have.width != s.vt.slots_x * ps || have.height != s.vt.slots_y * ps) {
      ImageDesc cd;
      cd.width = s.vt.slots_x * ps;
      cd.height = s.vt.slots_y * ps;
      cd.format = f;
      VT_ASSIGN_OR_RETURN(s.lit.caches[i], s.ctx.create_image(cd));
      VT_RETURN_IF_ERROR(s.ctx.submit_and_wait([&](VkCommandBuffer cmd) {
        VulkanContext::transition(cmd, s.lit.caches[i], VK_IMAGE_LAYOUT_UNDEFINED,
                                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      }));
      s.lit.formats[i] = formats[i];
    }
  }
  if (!s.lit.vt_pool) {
    VT_ASSIGN_OR_RETURN(s.lit.vt_pool, make_lit_pool(s.dev, 1, 5));
    VT_ASSIGN_OR_RETURN(s.lit.vt_set, s.allocate_set(s.lit.vt_pool, s.lit.vt_set_layout));
  }
  // The page table is made anew by every set_virtual_texture: bind the current one.
  const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  VkDescriptorImageInfo images[5] = {{s.table_sampler, s.table.view(), ro}};
  for (uint32_t i = 0; i < kLitInputCount; ++i) {
    // An unused input reads the blank image (the shader ignores it).
    const Image& img = s.lit.caches[i].handle() ? s.lit.caches[i] : s.lit.blank;
    images[i + 1] = {s.cache_sampler, img.view(), ro};
  }
  write_lit_set(s.dev, s.lit.vt_set, images, s.lit.frame);
  return Status::Ok();
}

Status Renderer::upload_lit_slots(LitInput input, std::span<const SlotUpload> pages) {
  Impl& s = *impl_;
  const uint32_t i = uint32_t(input);
  if (i >= kLitInputCount || !s.lit.formats[i]) {
    return Error(ErrorCode::kInvalidArgument, "render: no lit cache for that input");
  }
  if (pages.empty()) return Status::Ok();
  return s.upload_pages(s.lit.caches[i], *s.lit.formats[i], pages, "lit page");
}

Expected<ReferenceFrame> Renderer::render_lit_reference(const Camera& camera,
                                                        const LitFrameOptions& o) {
  Impl& s = *impl_;
  if (s.lit.materials.size() != s.textures.size() || s.textures.empty()) {
    return Error(ErrorCode::kInvalidArgument, "render: no lit materials set");
  }
  for (const auto& m : s.reference_meshes()) {
    if (m.texture >= s.lit.materials.size()) {
      return Error(ErrorCode::kInvalidArgument,
                   "render: a mesh names material " + std::to_string(m.texture) + " but only " +
                       std::to_string(s.lit.materials.size()) + " are set");
    }
  }
  fill_lit_frame(s.lit.frame, o);
  const uint32_t w = options_.width, h = options_.height;
  VT_RETURN_IF_ERROR(s.run_color_pass(w, h, s.lit.ref_pipe, true, [&](VkCommandBuffer cmd) {
    for (const auto& m : s.reference_meshes()) {
      const auto& t = s.textures[m.texture];
      const LitState::Material& lm = s.lit.materials[m.texture];
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.lit.ref_layout, 0, 1, &lm.set,
                              0, nullptr);
      Push p{};
      std::memcpy(p.mvp, camera.view_proj.m.data(), sizeof(p.mvp));
      p.tex[0] = float(t.width);
      p.tex[1] = float(t.height);
      p.tex[2] = 1.0f;
      p.tex[3] = m.alpha_cutoff;
      for (int c = 0; c < 3; ++c) p.vt[c] = float_bits(lm.emissive_scale[c]);
      p.vt[3] = float_bits(lm.normal_scale);
      p.misc[0] = lm.flags;
      p.misc[1] = t.sampler_addressing ? 2 : t.mode == AddressMode::kWrap ? 1 : 0;
      p.misc[2] = int32_t(t.max_level);
      p.misc[3] = lit_frame_bits(o);
      draw_mesh(cmd, s.lit.ref_layout, p, m);
    }
  }));
  ReferenceFrame out;
  out.color = s.read_color(w, h);
  out.covered = read_u32(s.status_rb, size_t(w) * h);
  out.depth = s.read_view_depth(camera, w, h);
  return out;
}

Expected<VirtualFrame> Renderer::render_lit_virtual(const Camera& camera,
                                                    const LitFrameOptions& o) {
  Impl& s = *impl_;
  if (!s.has_vt || !s.lit.vt_set) {
    return Error(ErrorCode::kInvalidArgument, "render: no lit caches set");
  }
  for (uint32_t i = 0; i < kLitInputCount; ++i) {
    if (((o.inputs >> i) & 1u) && !s.lit.formats[i]) {
      return Error(ErrorCode::kInvalidArgument,
                   "render: lit input " + std::to_string(i) + " has no cache");
    }
  }
  fill_lit_frame(s.lit.frame, o);
  const uint32_t w = options_.width, h = options_.height;
  VT_RETURN_IF_ERROR(s.run_color_pass(w, h, s.lit.vt_pipe, false, [&](VkCommandBuffer cmd) {
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.lit.vt_layout, 0, 1,
                            &s.lit.vt_set, 0, nullptr);
    for (const auto& m : s.meshes) {
      Push p{};
      std::memcpy(p.mvp, camera.view_proj.m.data(), sizeof(p.mvp));
      fill_vt_push(p, s.vt);
      p.tex[2] = 1.0f;
      p.tex[3] = m.alpha_cutoff;
      p.misc[3] = lit_frame_bits(o);
      draw_mesh(cmd, s.lit.vt_layout, p, m);
    }
  }));
  VirtualFrame out;
  out.color = s.read_color(w, h);
  out.status = read_u32(s.status_rb, size_t(w) * h);
  return out;
}

}  // namespace vt::render
