#include "lightmap_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>

// SPIR-V compiled from shaders/ at build time (CMakeLists.txt).
#include "engine_sample_spirv/lightmapped_frag.h"
#include "engine_sample_spirv/lightmapped_vert.h"

namespace engine_sample {
namespace {

constexpr VkFormat kColorFormat = VK_FORMAT_R32G32B32A32_SFLOAT;  // linear radiance, tone-mapped on the host

// The shaders' push constant block (128 bytes, the minimum every device offers).
struct DrawConstants {
  float view_projection[16];
  float scale_offset[4];
  float albedo[4];
  float emission[4];
  uint32_t flags[4];  // lightmapped, double-sided, mirrored
};
static_assert(sizeof(DrawConstants) == 128);

}  // namespace

LightmapRenderer::LightmapRenderer(const EngineDevice& device, const SceneGeometry& scene, uint32_t width,
                                   uint32_t height, std::span<const ExitanceRuntimePageImage> pages)
    : device_(device), vk_(device.device()), scene_(scene), width_(width), height_(height) {
  for (const Draw& d : scene.draws)
    if (d.lightmapped && d.page >= pages.size())
      throw std::runtime_error("an instance of the bundle uses page " + std::to_string(d.page) +
                               " but the runtime publishes " + std::to_string(pages.size()));
  if (pages.empty()) throw std::runtime_error("the runtime published no page images");

  // Depth: D32 float where the device has it (reversed-Z keeps its precision), else what Vulkan guarantees.
  for (VkFormat f : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D16_UNORM}) {
    VkFormatProperties p;
    vkGetPhysicalDeviceFormatProperties(device.physical_device(), f, &p);
    if (p.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) {
      depth_format_ = f;
      break;
    }
  }
  // Linear filtering of 32-bit float formats is optional in Vulkan (lavapipe and desktop GPUs have it).
  VkFormatProperties page_format;
  vkGetPhysicalDeviceFormatProperties(device.physical_device(), pages[0].format, &page_format);
  manual_bilinear_ = !(page_format.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT);

  color_ = make_image(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                      VK_IMAGE_ASPECT_COLOR_BIT);
  depth_ = make_image(depth_format_, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
  // Host-visible vertex and index buffers: the scene is small and drawn as loaded (an engine would stage them).
  vertices_ = make_buffer(std::max<VkDeviceSize>(4, scene.vertices.size() * sizeof(DrawVertex)),
                          VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, scene.vertices.data());
  indices_ = make_buffer(std::max<VkDeviceSize>(4, scene.indices.size() * sizeof(uint32_t)),
                         VK_BUFFER_USAGE_INDEX_BUFFER_BIT, scene.indices.data());
  readback_ = make_buffer(VkDeviceSize(width) * height * 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT, nullptr);
  create_render_pass();

  // Bilinear between texel centres, clamped to the edge: the loader's lookup (Bundle::lightmap).
  VkSamplerCreateInfo sampler{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sampler.magFilter = sampler.minFilter = manual_bilinear_ ? VK_FILTER_NEAREST : VK_FILTER_LINEAR;
  sampler.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sampler.addressModeU = sampler.addressModeV = sampler.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sampler.maxLod = 0.0f;
  check_vk(vkCreateSampler(vk_, &sampler, nullptr, &sampler_), "vkCreateSampler");

  // One set per page, bound per draw: an array of samplers indexed by a push constant would need
  // shaderSampledImageArrayDynamicIndexing, which lavapipe (Mesa 22) lacks.
  VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT,
                                       nullptr};
  VkDescriptorSetLayoutCreateInfo layout{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  layout.bindingCount = 1;
  layout.pBindings = &binding;
  check_vk(vkCreateDescriptorSetLayout(vk_, &layout, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
  VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, uint32_t(pages.size())};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.maxSets = uint32_t(pages.size());
  pool.poolSizeCount = 1;
  pool.pPoolSizes = &pool_size;
  check_vk(vkCreateDescriptorPool(vk_, &pool, nullptr, &pool_), "vkCreateDescriptorPool");
  const std::vector<VkDescriptorSetLayout> layouts(pages.size(), set_layout_);
  VkDescriptorSetAllocateInfo allocate{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  allocate.descriptorPool = pool_;
  allocate.descriptorSetCount = uint32_t(pages.size());
  allocate.pSetLayouts = layouts.data();
  sets_.resize(pages.size());
  check_vk(vkAllocateDescriptorSets(vk_, &allocate, sets_.data()), "vkAllocateDescriptorSets");
  bound_views_.assign(pages.size(), VK_NULL_HANDLE);
  set_pages(pages);
  create_pipeline();

  VkCommandPoolCreateInfo command_pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  command_pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  command_pool.queueFamilyIndex = device.queue_family();
  check_vk(vkCreateCommandPool(vk_, &command_pool, nullptr, &command_pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo commands{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  commands.commandPool = command_pool_;
  commands.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  commands.commandBufferCount = 1;
  check_vk(vkAllocateCommandBuffers(vk_, &commands, &commands_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check_vk(vkCreateFence(vk_, &fence, nullptr, &fence_), "vkCreateFence");
}

LightmapRenderer::~LightmapRenderer() {
  vkDeviceWaitIdle(vk_);  // every frame was waited for; this covers a failure between submit and wait
  vkDestroyFence(vk_, fence_, nullptr);
  vkDestroyCommandPool(vk_, command_pool_, nullptr);
  vkDestroyPipeline(vk_, pipeline_, nullptr);
  vkDestroyPipelineLayout(vk_, pipeline_layout_, nullptr);
  vkDestroyDescriptorPool(vk_, pool_, nullptr);
  vkDestroyDescriptorSetLayout(vk_, set_layout_, nullptr);
  vkDestroySampler(vk_, sampler_, nullptr);
  vkDestroyFramebuffer(vk_, framebuffer_, nullptr);
  vkDestroyRenderPass(vk_, render_pass_, nullptr);
  destroy(readback_);
  destroy(indices_);
  destroy(vertices_);
  destroy(depth_);
  destroy(color_);
}

uint32_t LightmapRenderer::memory_type(uint32_t type_bits, VkMemoryPropertyFlags wanted) const {
  VkPhysicalDeviceMemoryProperties properties;
  vkGetPhysicalDeviceMemoryProperties(device_.physical_device(), &properties);
  for (uint32_t i = 0; i < properties.memoryTypeCount; ++i)
    if ((type_bits & (1u << i)) && (properties.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  throw std::runtime_error("no Vulkan memory type with properties " + std::to_string(wanted));
}

LightmapRenderer::Buffer LightmapRenderer::make_buffer(VkDeviceSize size, VkBufferUsageFlags usage,
                                                       const void* contents) {
  Buffer b;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check_vk(vkCreateBuffer(vk_, &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(vk_, b.buffer, &requirements);
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.allocationSize = requirements.size;
  // Coherent: no flush after writing the vertices, no invalidate before reading a frame back.
  allocate.memoryTypeIndex = memory_type(requirements.memoryTypeBits,
                                         VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  check_vk(vkAllocateMemory(vk_, &allocate, nullptr, &b.memory), "vkAllocateMemory");
  check_vk(vkBindBufferMemory(vk_, b.buffer, b.memory, 0), "vkBindBufferMemory");
  check_vk(vkMapMemory(vk_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  if (contents) std::memcpy(b.mapped, contents, size_t(size));
  return b;
}

LightmapRenderer::Image LightmapRenderer::make_image(VkFormat format, VkImageUsageFlags usage,
                                                     VkImageAspectFlags aspect) {
  Image i;
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width_, height_, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check_vk(vkCreateImage(vk_, &info, nullptr, &i.image), "vkCreateImage");
  VkMemoryRequirements requirements;
  vkGetImageMemoryRequirements(vk_, i.image, &requirements);
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = memory_type(requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check_vk(vkAllocateMemory(vk_, &allocate, nullptr, &i.memory), "vkAllocateMemory");
  check_vk(vkBindImageMemory(vk_, i.image, i.memory, 0), "vkBindImageMemory");
  VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view.image = i.image;
  view.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view.format = format;
  view.subresourceRange = {aspect, 0, 1, 0, 1};
  check_vk(vkCreateImageView(vk_, &view, nullptr, &i.view), "vkCreateImageView");
  return i;
}

void LightmapRenderer::destroy(Buffer& b) {
  if (b.buffer) vkDestroyBuffer(vk_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(vk_, b.memory, nullptr);
  b = {};
}

void LightmapRenderer::destroy(Image& i) {
  if (i.view) vkDestroyImageView(vk_, i.view, nullptr);
  if (i.image) vkDestroyImage(vk_, i.image, nullptr);
  if (i.memory) vkFreeMemory(vk_, i.memory, nullptr);
  i = {};
}

void LightmapRenderer::create_render_pass() {
  VkAttachmentDescription attachments[2]{};
  attachments[0].format = kColorFormat;
  attachments[0].samples = VK_SAMPLE_COUNT_1_BIT;
  attachments[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  attachments[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachments[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  attachments[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachments[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  attachments[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;  // copied to the host after the pass
  attachments[1] = attachments[0];
  attachments[1].format = depth_format_;
  attachments[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachments[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  VkAttachmentReference color{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkAttachmentReference depth{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &color;
  subpass.pDepthStencilAttachment = &depth;
  // Before: the previous frame's copy read the colour target. After: this frame's copy reads it.
  VkSubpassDependency dependencies[2]{};
  dependencies[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  dependencies[0].dstSubpass = 0;
  dependencies[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dependencies[0].srcAccessMask = 0;  // a write-after-read needs only the execution dependency
  dependencies[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                                 VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  dependencies[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                                  VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  dependencies[1].srcSubpass = 0;
  dependencies[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  dependencies[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dependencies[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  dependencies[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dependencies[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = 2;
  info.pAttachments = attachments;
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = 2;
  info.pDependencies = dependencies;
  check_vk(vkCreateRenderPass(vk_, &info, nullptr, &render_pass_), "vkCreateRenderPass");
  const VkImageView views[2] = {color_.view, depth_.view};
  VkFramebufferCreateInfo framebuffer{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  framebuffer.renderPass = render_pass_;
  framebuffer.attachmentCount = 2;
  framebuffer.pAttachments = views;
  framebuffer.width = width_;
  framebuffer.height = height_;
  framebuffer.layers = 1;
  check_vk(vkCreateFramebuffer(vk_, &framebuffer, nullptr, &framebuffer_), "vkCreateFramebuffer");
}

void LightmapRenderer::create_pipeline() {
  VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(DrawConstants)};
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout.setLayoutCount = 1;
  layout.pSetLayouts = &set_layout_;
  layout.pushConstantRangeCount = 1;
  layout.pPushConstantRanges = &push;
  check_vk(vkCreatePipelineLayout(vk_, &layout, nullptr, &pipeline_layout_), "vkCreatePipelineLayout");

  VkShaderModule modules[2]{};
  const std::pair<const uint32_t*, size_t> code[2] = {{spirv_lightmapped_vert, sizeof(spirv_lightmapped_vert)},
                                                      {spirv_lightmapped_frag, sizeof(spirv_lightmapped_frag)}};
  for (int s = 0; s < 2; ++s) {
    VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = code[s].second;
    info.pCode = code[s].first;
    check_vk(vkCreateShaderModule(vk_, &info, nullptr, &modules[s]), "vkCreateShaderModule");
  }
  const VkBool32 manual = manual_bilinear_ ? VK_TRUE : VK_FALSE;
  VkSpecializationMapEntry entry{0, 0, sizeof(VkBool32)};
  VkSpecializationInfo specialization{1, &entry, sizeof(manual), &manual};
  VkPipelineShaderStageCreateInfo stages[2]{};
  for (int s = 0; s < 2; ++s) {
    stages[s].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[s].stage = s == 0 ? VK_SHADER_STAGE_VERTEX_BIT : VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[s].module = modules[s];
    stages[s].pName = "main";
  }
  stages[1].pSpecializationInfo = &specialization;

  VkVertexInputBindingDescription binding{0, sizeof(DrawVertex), VK_VERTEX_INPUT_RATE_VERTEX};
  VkVertexInputAttributeDescription attributes[2] = {
      {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(DrawVertex, position)},
      {1, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(DrawVertex, lightmap_uv)}};
  VkPipelineVertexInputStateCreateInfo vertex_input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vertex_input.vertexBindingDescriptionCount = 1;
  vertex_input.pVertexBindingDescriptions = &binding;
  vertex_input.vertexAttributeDescriptionCount = 2;
  vertex_input.pVertexAttributeDescriptions = attributes;
  VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  // A positive-height viewport: framebuffer y grows downwards; the projection flips y (pinhole_camera.h).
  VkViewport viewport{0, 0, float(width_), float(height_), 0, 1};
  VkRect2D scissor{{0, 0}, {width_, height_}};
  VkPipelineViewportStateCreateInfo viewport_state{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport_state.viewportCount = 1;
  viewport_state.pViewports = &viewport;
  viewport_state.scissorCount = 1;
  viewport_state.pScissors = &scissor;
  // No culling: a single-sided surface seen from behind is drawn black (the fragment shader), as
  // exitance-view shows it, so it still hides what lies behind it. Counter-clockwise as seen in the
  // image (row 0 at the top) is glTF's front face.
  VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  // One sample at each pixel centre, as exitance-view's --aa 1 casts one ray through it.
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  depth.depthTestEnable = VK_TRUE;
  depth.depthWriteEnable = VK_TRUE;
  depth.depthCompareOp = VK_COMPARE_OP_GREATER;  // reversed Z
  VkPipelineColorBlendAttachmentState blend_attachment{};
  blend_attachment.colorWriteMask =
      VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blend.attachmentCount = 1;
  blend.pAttachments = &blend_attachment;

  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &vertex_input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport_state;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blend;
  info.layout = pipeline_layout_;
  info.renderPass = render_pass_;
  info.subpass = 0;
  const VkResult result = vkCreateGraphicsPipelines(vk_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
  for (VkShaderModule m : modules) vkDestroyShaderModule(vk_, m, nullptr);
  check_vk(result, "vkCreateGraphicsPipelines");
}

void LightmapRenderer::set_pages(std::span<const ExitanceRuntimePageImage> pages) {
  if (pages.size() != sets_.size()) throw std::runtime_error("the runtime's page count changed");
  for (size_t p = 0; p < pages.size(); ++p) {
    if (pages[p].view == bound_views_[p]) continue;
    // The runtime keeps the pages in VK_IMAGE_LAYOUT_GENERAL and says so in `layout`.
    VkDescriptorImageInfo image{sampler_, pages[p].view, pages[p].layout};
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstSet = sets_[p];
    write.dstBinding = 0;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    write.pImageInfo = &image;
    vkUpdateDescriptorSets(vk_, 1, &write, 0, nullptr);
    bound_views_[p] = pages[p].view;
  }
}

void LightmapRenderer::record(const std::array<float, 16>& view_projection) {
  check_vk(vkResetCommandBuffer(commands_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check_vk(vkBeginCommandBuffer(commands_, &begin), "vkBeginCommandBuffer");
  VkClearValue clears[2]{};
  clears[0].color = {{0.0f, 0.0f, 0.0f, 1.0f}};  // a miss is black: the sample draws no sky
  clears[1].depthStencil = {0.0f, 0};            // reversed Z: 0 is infinitely far
  VkRenderPassBeginInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  pass.renderPass = render_pass_;
  pass.framebuffer = framebuffer_;
  pass.renderArea = {{0, 0}, {width_, height_}};
  pass.clearValueCount = 2;
  pass.pClearValues = clears;
  vkCmdBeginRenderPass(commands_, &pass, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
  const VkDeviceSize offset = 0;
  vkCmdBindVertexBuffers(commands_, 0, 1, &vertices_.buffer, &offset);
  vkCmdBindIndexBuffer(commands_, indices_.buffer, 0, VK_INDEX_TYPE_UINT32);
  int64_t bound_page = -1;
  for (const Draw& d : scene_.draws) {
    // Draws without a lightmap read none, but the layout's set must be bound: any page will do.
    const uint32_t page = d.lightmapped ? d.page : uint32_t(std::max<int64_t>(bound_page, 0));
    if (int64_t(page) != bound_page) {
      vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_layout_, 0, 1, &sets_[page], 0,
                              nullptr);
      bound_page = page;
    }
    DrawConstants c{};
    std::memcpy(c.view_projection, view_projection.data(), sizeof c.view_projection);
    std::memcpy(c.scale_offset, d.scale_offset.data(), sizeof c.scale_offset);
    std::memcpy(c.albedo, d.albedo.data(), 3 * sizeof(float));
    std::memcpy(c.emission, d.emission.data(), 3 * sizeof(float));
    c.flags[0] = d.lightmapped, c.flags[1] = d.double_sided, c.flags[2] = d.mirrored;
    vkCmdPushConstants(commands_, pipeline_layout_, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                       sizeof c, &c);
    vkCmdDrawIndexed(commands_, d.index_count, 1, d.first_index, d.vertex_offset, 0);
  }
  vkCmdEndRenderPass(commands_);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {width_, height_, 1};
  vkCmdCopyImageToBuffer(commands_, color_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.buffer, 1, &copy);
  VkBufferMemoryBarrier to_host{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  to_host.srcQueueFamilyIndex = to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_host.buffer = readback_.buffer;
  to_host.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1,
                       &to_host, 0, nullptr);
  check_vk(vkEndCommandBuffer(commands_), "vkEndCommandBuffer");
}

std::vector<float> LightmapRenderer::render(const std::array<float, 16>& view_projection,
                                            const ExitanceRuntimeImagesReady& ready, double timeout_seconds) {
  // The pages are exclusive to the family the runtime wrote them on; this sample renders on the
  // queue it lent the runtime, so no ownership transfer is needed.
  if (ready.semaphore != VK_NULL_HANDLE && ready.queue_family != device_.queue_family())
    throw std::runtime_error("the page images belong to queue family " + std::to_string(ready.queue_family) +
                             ", not the sample's " + std::to_string(device_.queue_family()));
  record(view_projection);
  // Wait for the runtime's writes where the lightmap is first read; the semaphore signal and wait
  // also make those writes visible to the fragment shader.
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
  VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  timeline.waitSemaphoreValueCount = 1;
  timeline.pWaitSemaphoreValues = &ready.value;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  if (ready.semaphore != VK_NULL_HANDLE) {
    submit.pNext = &timeline;
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &ready.semaphore;
    submit.pWaitDstStageMask = &wait_stage;
  }
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands_;
  check_vk(vkResetFences(vk_, 1, &fence_), "vkResetFences");
  check_vk(vkQueueSubmit(device_.queue(), 1, &submit, fence_), "vkQueueSubmit");
  const VkResult waited = vkWaitForFences(vk_, 1, &fence_, VK_TRUE, uint64_t(timeout_seconds * 1e9));
  if (waited == VK_TIMEOUT)
    throw FrameTimeout("the frame did not finish within " + std::to_string(int(timeout_seconds)) + " s");
  check_vk(waited, "vkWaitForFences");
  const float* pixels = static_cast<const float*>(readback_.mapped);
  return std::vector<float>(pixels, pixels + size_t(width_) * height_ * 4);
}

}  // namespace engine_sample
