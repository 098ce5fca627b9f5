// The engine's frame: the scene drawn offscreen with a classic render pass and one graphics
// pipeline, sampling the runtime's lightmap page images where they are (no host read-back of the
// lightmap), then the colour target copied to the host for the PNG.
#pragma once
#include <vulkan/vulkan.h>

#include <array>
#include <span>
#include <stdexcept>
#include <vector>

#include "engine_device.h"
#include "gltf_geometry.h"

namespace engine_sample {

// A frame did not finish in time: the device may still use every resource, so nothing may be
// destroyed; main exits at once.
class FrameTimeout : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LightmapRenderer {
 public:
  // `pages`: what exitance_runtime_publish_page_images described (one descriptor set each).
  LightmapRenderer(const EngineDevice& device, const SceneGeometry& scene, uint32_t width, uint32_t height,
                   std::span<const ExitanceRuntimePageImage> pages);
  ~LightmapRenderer();
  LightmapRenderer(const LightmapRenderer&) = delete;
  LightmapRenderer& operator=(const LightmapRenderer&) = delete;

  // Points the descriptor sets at `pages` where a view changed (the runtime promises the same images
  // on every call; an engine that does not rely on it rewrites them between frames like this).
  void set_pages(std::span<const ExitanceRuntimePageImage> pages);

  // Draws the scene once `ready` is reached (its semaphore waited on at the fragment shader stage) and
  // returns the frame: linear RGBA floats, row 0 at the top. Waits at most `timeout_seconds`.
  std::vector<float> render(const std::array<float, 16>& view_projection, const ExitanceRuntimeImagesReady& ready,
                            double timeout_seconds);

  bool manual_bilinear() const { return manual_bilinear_; }

 private:
  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
  };
  struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };

  uint32_t memory_type(uint32_t type_bits, VkMemoryPropertyFlags wanted) const;
  Buffer make_buffer(VkDeviceSize size, VkBufferUsageFlags usage, const void* contents);
  Image make_image(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect);
  void destroy(Buffer& b);
  void destroy(Image& i);
  void create_render_pass();
  void create_pipeline();
  void record(const std::array<float, 16>& view_projection);

  const EngineDevice& device_;
  VkDevice vk_;
  const SceneGeometry& scene_;
  uint32_t width_, height_;
  VkFormat depth_format_ = VK_FORMAT_UNDEFINED;
  bool manual_bilinear_ = false;
  Image color_, depth_;
  Buffer vertices_, indices_, readback_;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
  VkSampler sampler_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorSet> sets_;  // one per page
  std::vector<VkImageView> bound_views_;
  VkPipelineLayout pipeline_layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
};

}  // namespace engine_sample
