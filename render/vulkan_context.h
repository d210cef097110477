// Headless Vulkan 1.3 context for the validation renderer: instance, device, one queue, a
// command pool, and move-only buffers and images with their memory. Every VkResult is checked
// and turned into a Status; no window, no swapchain.
//
// Device choice: Mesa's lavapipe (driverID VK_DRIVER_ID_MESA_LLVMPIPE) unless the caller asks
// for a hardware device. When the user has not set VK_DRIVER_FILES / VK_ICD_FILENAMES they are
// pointed at lavapipe's ICD first (instance creation drops from ~320 ms to ~40 ms), unless a
// hardware device is wanted.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "common/status.h"

namespace vt::render {

struct VulkanOptions {
  bool prefer_hardware = false;  // pick a discrete/integrated GPU when one exists
  bool validation = false;       // enable VK_LAYER_KHRONOS_validation if installed
};

// Turns a VkResult into a Status naming the call that failed.
Status vk_status(VkResult result, const char* what);
const char* vk_result_name(VkResult result);

class VulkanContext;

// A buffer and its own memory allocation. Host-visible buffers stay mapped.
class Buffer {
 public:
  Buffer() = default;
  Buffer(Buffer&& other) noexcept { *this = std::move(other); }
  Buffer& operator=(Buffer&& other) noexcept;
  ~Buffer() { reset(); }
  void reset();

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  uint8_t* mapped() const { return mapped_; }  // null unless host-visible

 private:
  friend class VulkanContext;
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  uint8_t* mapped_ = nullptr;
};

struct ImageDesc {
  uint32_t width = 1;
  uint32_t height = 1;
  uint32_t mip_levels = 1;
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  VkImageUsageFlags usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
};

// A device-local optimal-tiling 2D image, its memory and a view of all its mips.
class Image {
 public:
  Image() = default;
  Image(Image&& other) noexcept { *this = std::move(other); }
  Image& operator=(Image&& other) noexcept;
  ~Image() { reset(); }
  void reset();

  VkImage handle() const { return image_; }
  VkImageView view() const { return view_; }
  const ImageDesc& desc() const { return desc_; }

 private:
  friend class VulkanContext;
  VkDevice device_ = VK_NULL_HANDLE;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  ImageDesc desc_;
};

// One region of a buffer -> image copy (tightly packed rows).
struct ImageCopy {
  VkDeviceSize buffer_offset = 0;
  uint32_t mip = 0;
  int32_t x = 0, y = 0;
  uint32_t width = 0, height = 0;
};

class VulkanContext {
 public:
  // kUnsupported when no usable Vulkan 1.3 device exists (no loader, no ICD, no device): callers
  // (and tests) treat that as "cannot validate here", not as a failed bake.
  static Expected<std::unique_ptr<VulkanContext>> create(const VulkanOptions& options = {});
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  VkDevice device() const { return device_; }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkQueue queue() const { return queue_; }
  const std::string& device_name() const { return device_name_; }
  bool is_lavapipe() const { return lavapipe_; }

  Expected<Buffer> create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible);
  // A host-visible buffer holding a copy of `bytes`.
  Expected<Buffer> create_buffer_with(std::span<const uint8_t> bytes, VkBufferUsageFlags usage);
  Expected<Image> create_image(const ImageDesc& desc);
  // True when `format` can be sampled with linear filtering from an optimal-tiling image.
  bool supports_sampled_linear(VkFormat format) const;

  // Records commands with `record`, submits them and waits for completion.
  Status submit_and_wait(const std::function<void(VkCommandBuffer)>& record);

  // Whole-image layout transition for all mips (sync2, conservative ALL_COMMANDS stages).
  static void transition(VkCommandBuffer cmd, const Image& image, VkImageLayout from,
                         VkImageLayout to);
  // Copies regions of `src` into `image` (which must be in TRANSFER_DST_OPTIMAL).
  static void copy_buffer_to_image(VkCommandBuffer cmd, const Buffer& src, const Image& image,
                                   std::span<const ImageCopy> regions);

 private:
  VulkanContext() = default;
  Expected<uint32_t> find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags flags) const;

  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_props_{};
  std::string device_name_;
  bool lavapipe_ = false;
};

}  // namespace vt::render
