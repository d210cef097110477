#include "render/vulkan_context.h"

#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

namespace vt::render {
namespace {

constexpr const char* kLavapipeIcd = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";

// Points the loader at lavapipe's ICD only when the user chose nothing and the file exists, so
// a user's own driver selection always wins.
void default_to_lavapipe() {
  if (std::getenv("VK_DRIVER_FILES") || std::getenv("VK_ICD_FILENAMES")) return;
  if (FILE* f = std::fopen(kLavapipeIcd, "r")) {
    std::fclose(f);
    setenv("VK_DRIVER_FILES", kLavapipeIcd, 0);
    setenv("VK_ICD_FILENAMES", kLavapipeIcd, 0);
  }
}

bool has_layer(const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  for (const auto& l : layers) {
    if (std::strcmp(l.layerName, name) == 0) return true;
  }
  return false;
}

}  // namespace

const char* vk_result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS:
      return "VK_SUCCESS";
    case VK_NOT_READY:
      return "VK_NOT_READY";
    case VK_TIMEOUT:
      return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
      return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
      return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
      return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
      return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED:
      return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT:
      return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
      return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
      return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS:
      return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED:
      return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    default:
      return "VkResult error";
  }
}

Status vk_status(VkResult result, const char* what) {
  if (result == VK_SUCCESS) return Status::Ok();
  ErrorCode code = ErrorCode::kInternal;
  if (result == VK_ERROR_OUT_OF_HOST_MEMORY || result == VK_ERROR_OUT_OF_DEVICE_MEMORY ||
      result == VK_ERROR_TOO_MANY_OBJECTS) {
    code = ErrorCode::kResourceLimit;
  } else if (result == VK_ERROR_INCOMPATIBLE_DRIVER || result == VK_ERROR_INITIALIZATION_FAILED ||
             result == VK_ERROR_FORMAT_NOT_SUPPORTED || result == VK_ERROR_FEATURE_NOT_PRESENT ||
             result == VK_ERROR_EXTENSION_NOT_PRESENT) {
    code = ErrorCode::kUnsupported;
  }
  return Error(code, std::string("vulkan: ") + what + " failed: " + vk_result_name(result) + " (" +
                         std::to_string(int(result)) + ")");
}

#define VT_VK(call) VT_RETURN_IF_ERROR(vk_status((call), #call))

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    reset();
    device_ = o.device_;
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(o.size_, 0);
    mapped_ = std::exchange(o.mapped_, nullptr);
  }
  return *this;
}

void Buffer::reset() {
  if (device_ == VK_NULL_HANDLE) return;
  if (VkBuffer b = std::exchange(buffer_, VK_NULL_HANDLE)) vkDestroyBuffer(device_, b, nullptr);
  // Freeing the memory unmaps it.
  if (VkDeviceMemory m = std::exchange(memory_, VK_NULL_HANDLE)) vkFreeMemory(device_, m, nullptr);
  mapped_ = nullptr;
  size_ = 0;
}

Image& Image::operator=(Image&& o) noexcept {
  if (this != &o) {
    reset();
    device_ = o.device_;
    desc_ = o.desc_;
    image_ = std::exchange(o.image_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    view_ = std::exchange(o.view_, VK_NULL_HANDLE);
  }
  return *this;
}

void Image::reset() {
  if (device_ == VK_NULL_HANDLE) return;
  if (VkImageView v = std::exchange(view_, VK_NULL_HANDLE)) vkDestroyImageView(device_, v, nullptr);
  if (VkImage i = std::exchange(image_, VK_NULL_HANDLE)) vkDestroyImage(device_, i, nullptr);
  if (VkDeviceMemory m = std::exchange(memory_, VK_NULL_HANDLE)) vkFreeMemory(device_, m, nullptr);
}

Expected<std::unique_ptr<VulkanContext>> VulkanContext::create(const VulkanOptions& options) {
  if (!options.prefer_hardware) default_to_lavapipe();
  std::unique_ptr<VulkanContext> ctx(new VulkanContext());

  uint32_t api = 0;
  if (vkEnumerateInstanceVersion(&api) != VK_SUCCESS || api < VK_API_VERSION_1_3) {
    return Error(ErrorCode::kUnsupported, "vulkan: the loader does not offer Vulkan 1.3");
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "vtbake-validate";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  const char* layer = "VK_LAYER_KHRONOS_validation";
  if (options.validation && has_layer(layer)) {
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = &layer;
  }
  VkResult r = vkCreateInstance(&ici, nullptr, &ctx->instance_);
  if (r != VK_SUCCESS) {
    return vk_status(r, "vkCreateInstance").with_context("no usable Vulkan driver");
  }

  uint32_t count = 0;
  VT_VK(vkEnumeratePhysicalDevices(ctx->instance_, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  VT_VK(vkEnumeratePhysicalDevices(ctx->instance_, &count, devices.data()));
  int best_score = -1;
  for (VkPhysicalDevice pd : devices) {
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &driver;
    vkGetPhysicalDeviceProperties2(pd, &props);
    if (props.properties.apiVersion < VK_API_VERSION_1_3) continue;
    bool lvp = driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE;
    bool hw = props.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ||
              props.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU;
    int score = options.prefer_hardware ? (hw ? 3 : lvp ? 2 : 1) : (lvp ? 3 : hw ? 2 : 1);
    if (score > best_score) {
      best_score = score;
      ctx->physical_ = pd;
      ctx->device_name_ = props.properties.deviceName;
      ctx->lavapipe_ = lvp;
    }
  }
  if (ctx->physical_ == VK_NULL_HANDLE) {
    return Error(ErrorCode::kUnsupported,
                 "vulkan: no Vulkan 1.3 device found (install "
                 "mesa-vulkan-drivers for lavapipe)");
  }

  uint32_t qcount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(ctx->physical_, &qcount, nullptr);
  std::vector<VkQueueFamilyProperties> families(qcount);
  vkGetPhysicalDeviceQueueFamilyProperties(ctx->physical_, &qcount, families.data());
  bool found = false;
  for (uint32_t i = 0; i < qcount; ++i) {
    if (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
      ctx->queue_family_ = i;
      found = true;
      break;
    }
  }
  if (!found) {
    return Error(ErrorCode::kUnsupported,
                 "vulkan: device " + ctx->device_name_ + " has no graphics queue");
  }

  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  f2.pNext = &f13;
  vkGetPhysicalDeviceFeatures2(ctx->physical_, &f2);
  if (!f13.dynamicRendering || !f13.synchronization2) {
    return Error(ErrorCode::kUnsupported, "vulkan: device " + ctx->device_name_ +
                                              " lacks dynamic rendering or synchronization2");
  }
  VkPhysicalDeviceVulkan13Features want13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  want13.dynamicRendering = VK_TRUE;
  want13.synchronization2 = VK_TRUE;
  VkPhysicalDeviceFeatures2 want{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  want.pNext = &want13;
  want.features.textureCompressionBC = f2.features.textureCompressionBC;

  float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = ctx->queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = &want;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  VT_VK(vkCreateDevice(ctx->physical_, &dci, nullptr, &ctx->device_));
  vkGetDeviceQueue(ctx->device_, ctx->queue_family_, 0, &ctx->queue_);
  vkGetPhysicalDeviceMemoryProperties(ctx->physical_, &ctx->memory_props_);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = ctx->queue_family_;
  VT_VK(vkCreateCommandPool(ctx->device_, &pci, nullptr, &ctx->pool_));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VT_VK(vkCreateFence(ctx->device_, &fci, nullptr, &ctx->fence_));
  return ctx;
}

VulkanContext::~VulkanContext() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

Expected<uint32_t> VulkanContext::find_memory_type(uint32_t type_bits,
                                                   VkMemoryPropertyFlags flags) const {
  for (uint32_t i = 0; i < memory_props_.memoryTypeCount; ++i) {
    if ((type_bits & (1u << i)) && (memory_props_.memoryTypes[i].propertyFlags & flags) == flags) {
      return i;
    }
  }
  return Error(ErrorCode::kUnsupported, "vulkan: no memory type with the required properties");
}

Expected<Buffer> VulkanContext::create_buffer(VkDeviceSize size, VkBufferUsageFlags usage,
                                              bool host_visible) {
  Buffer b;
  b.device_ = device_;
  b.size_ = size;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size == 0 ? 4 : size;
  bci.usage = usage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VT_VK(vkCreateBuffer(device_, &bci, nullptr, &b.buffer_));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer_, &req);
  VkMemoryPropertyFlags flags =
      host_visible ? (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)
                   : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  VT_ASSIGN_OR_RETURN(uint32_t type, find_memory_type(req.memoryTypeBits, flags));
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  VT_VK(vkAllocateMemory(device_, &mai, nullptr, &b.memory_));
  VT_VK(vkBindBufferMemory(device_, b.buffer_, b.memory_, 0));
  if (host_visible) {
    void* p = nullptr;
    VT_VK(vkMapMemory(device_, b.memory_, 0, VK_WHOLE_SIZE, 0, &p));
    b.mapped_ = static_cast<uint8_t*>(p);
  }
  return b;
}

Expected<Buffer> VulkanContext::create_buffer_with(std::span<const uint8_t> bytes,
                                                   VkBufferUsageFlags usage) {
  VT_ASSIGN_OR_RETURN(Buffer b, create_buffer(bytes.size(), usage, true));
  if (!bytes.empty()) std::memcpy(b.mapped(), bytes.data(), bytes.size());
  return b;
}

Expected<Image> VulkanContext::create_image(const ImageDesc& desc) {
  if (desc.width == 0 || desc.height == 0 || desc.mip_levels == 0) {
    return Error(ErrorCode::kInvalidArgument, "vulkan: empty image");
  }
  VkImageFormatProperties ifp;
  VkResult fr = vkGetPhysicalDeviceImageFormatProperties(
      physical_, desc.format, VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL, desc.usage, 0, &ifp);
  if (fr != VK_SUCCESS || desc.width > ifp.maxExtent.width || desc.height > ifp.maxExtent.height ||
      desc.mip_levels > ifp.maxMipLevels) {
    return Error(ErrorCode::kUnsupported, "vulkan: image " + std::to_string(desc.width) + "x" +
                                              std::to_string(desc.height) + " of format " +
                                              std::to_string(desc.format) +
                                              " is not supported by " + device_name_);
  }
  Image img;
  img.device_ = device_;
  img.desc_ = desc;
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = desc.format;
  ci.extent = {desc.width, desc.height, 1};
  ci.mipLevels = desc.mip_levels;
  ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = desc.usage;
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VT_VK(vkCreateImage(device_, &ci, nullptr, &img.image_));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device_, img.image_, &req);
  VT_ASSIGN_OR_RETURN(uint32_t type,
                      find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT));
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  VT_VK(vkAllocateMemory(device_, &mai, nullptr, &img.memory_));
  VT_VK(vkBindImageMemory(device_, img.image_, img.memory_, 0));
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = img.image_;
  vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vci.format = desc.format;
  vci.subresourceRange = {desc.aspect, 0, desc.mip_levels, 0, 1};
  VT_VK(vkCreateImageView(device_, &vci, nullptr, &img.view_));
  return img;
}

bool VulkanContext::supports_sampled_linear(VkFormat format) const {
  VkFormatProperties p;
  vkGetPhysicalDeviceFormatProperties(physical_, format, &p);
  return (p.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;
}

Status VulkanContext::submit_and_wait(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  VT_VK(vkAllocateCommandBuffers(device_, &ai, &cmd));
  struct Free {
    VkDevice d;
    VkCommandPool p;
    VkCommandBuffer c;
    ~Free() { vkFreeCommandBuffers(d, p, 1, &c); }
  } free_cmd{device_, pool_, cmd};
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VT_VK(vkBeginCommandBuffer(cmd, &bi));
  record(cmd);
  VT_VK(vkEndCommandBuffer(cmd));
  VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cbi.commandBuffer = cmd;
  VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  si.commandBufferInfoCount = 1;
  si.pCommandBufferInfos = &cbi;
  VT_VK(vkResetFences(device_, 1, &fence_));
  VT_VK(vkQueueSubmit2(queue_, 1, &si, fence_));
  VT_VK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
  return Status::Ok();
}

void VulkanContext::transition(VkCommandBuffer cmd, const Image& image, VkImageLayout from,
                               VkImageLayout to) {
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  b.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
  b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image.handle();
  b.subresourceRange = {image.desc().aspect, 0, image.desc().mip_levels, 0, 1};
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = 1;
  dep.pImageMemoryBarriers = &b;
  vkCmdPipelineBarrier2(cmd, &dep);
}

void VulkanContext::copy_buffer_to_image(VkCommandBuffer cmd, const Buffer& src, const Image& image,
                                         std::span<const ImageCopy> regions) {
  std::vector<VkBufferImageCopy> copies;
  copies.reserve(regions.size());
  for (const ImageCopy& r : regions) {
    VkBufferImageCopy c{};
    c.bufferOffset = r.buffer_offset;
    c.imageSubresource = {image.desc().aspect, r.mip, 0, 1};
    c.imageOffset = {r.x, r.y, 0};
    c.imageExtent = {r.width, r.height, 1};
    copies.push_back(c);
  }
  if (copies.empty()) return;
  vkCmdCopyBufferToImage(cmd, src.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         uint32_t(copies.size()), copies.data());
}

}  // namespace vt::render
