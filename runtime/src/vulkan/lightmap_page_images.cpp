#include "lightmap_page_images.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "exitance_spirv/page_images.h"

namespace exitance::vulkan {
namespace {

struct PageImagesPush {
  uint32_t width, height, first_pixel, ring;
};

constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

}  // namespace

PagePixelRings page_pixel_rings(const TexelGBuffer& gbuffer, size_t page, int dilation_texels) {
  const AtlasPage& source = gbuffer.pages.at(page);
  const int w = source.width, h = source.height;
  const size_t n = size_t(w) * size_t(h);
  PagePixelRings result;
  result.texel.assign(n, PagePixelRings::kNoTexel);
  result.ring.assign(n, PagePixelRings::kNeverFilled);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    if (t.page == page) result.texel[size_t(t.y) * size_t(w) + t.x] = uint32_t(i);
  }
  // dilate_into_gutter: chart pixels (coverage > 0) are filled; pass k fills every other pixel
  // with a neighbour filled before it, up to `dilation_texels` passes or until none is filled.
  for (size_t i = 0; i < n; ++i)
    if (source.coverage[i] > 0) result.ring[i] = 0;
  for (uint32_t k = 1; int(k) <= dilation_texels; ++k) {
    bool any = false;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        if (result.ring[i] != PagePixelRings::kNeverFilled) continue;
        bool next_to_filled = false;
        for (int dy = -1; dy <= 1 && !next_to_filled; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
            if (result.ring[size_t(ny) * size_t(w) + size_t(nx)] < k) {
              next_to_filled = true;
              break;
            }
          }
        if (next_to_filled) result.ring[i] = k, any = true;
      }
    if (!any) break;
    result.rings = k;
  }
  return result;
}

LightmapPageImages::LightmapPageImages(Context& context, const TexelGBuffer& gbuffer, int dilation_texels)
    : context_(context),
      texels_(gbuffer.texels.size()),
      dilation_(dilation_texels),
      kernel_(context,
              {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
               VK_DESCRIPTOR_TYPE_STORAGE_IMAGE},
              sizeof(PageImagesPush), spirv_page_images, sizeof(spirv_page_images),
              uint32_t(std::max<size_t>(gbuffer.pages.size(), 1)), "page_images.comp") {
  VkDevice d = context.device();
  try {
    // Which texel each pixel shows and its ring, all pages in one buffer.
    std::vector<uint32_t> pixels;
    for (size_t p = 0; p < gbuffer.pages.size(); ++p) {
      const PagePixelRings rings = page_pixel_rings(gbuffer, p, dilation_texels);
      first_pixel_.push_back(uint32_t(pixels.size() / 3));
      rings_.push_back(rings.rings);
      const std::vector<float>& coverage = gbuffer.pages[p].coverage;
      for (size_t i = 0; i < rings.texel.size(); ++i) {
        uint32_t bits;
        std::memcpy(&bits, &coverage[i], 4);
        pixels.insert(pixels.end(), {rings.texel[i], rings.ring[i], bits});
      }
    }
    pixels_ = context.create_storage_buffer(std::max<size_t>(pixels.size() * 4, 16));
    if (!pixels.empty()) context.upload(pixels_, pixels.data(), pixels.size() * 4);

    images_.format = kFormat;
    images_.layout = VK_IMAGE_LAYOUT_GENERAL;
    images_.queue_family = context.queue_family();
    // Shared by every queue family of the device, so an engine reading them on another family
    // needs no ownership transfer (only the semaphore wait).
    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(context.physical_device(), &family_count, nullptr);
    std::vector<uint32_t> families(family_count);
    for (uint32_t f = 0; f < family_count; ++f) families[f] = f;
    for (const AtlasPage& page : gbuffer.pages) {
      DevicePageImage image;
      image.width = uint32_t(page.width);
      image.height = uint32_t(page.height);
      VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
      info.imageType = VK_IMAGE_TYPE_2D;
      info.format = kFormat;
      info.extent = {image.width, image.height, 1};
      info.mipLevels = 1;
      info.arrayLayers = 1;
      info.samples = VK_SAMPLE_COUNT_1_BIT;
      info.tiling = VK_IMAGE_TILING_OPTIMAL;
      info.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
      info.sharingMode = family_count > 1 ? VK_SHARING_MODE_CONCURRENT : VK_SHARING_MODE_EXCLUSIVE;
      if (family_count > 1) info.queueFamilyIndexCount = family_count, info.pQueueFamilyIndices = families.data();
      info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
      check(vkCreateImage(d, &info, nullptr, &image.image), "vkCreateImage (a lightmap page)");
      images_.pages.push_back(image);
      VkMemoryRequirements requirements;
      vkGetImageMemoryRequirements(d, image.image, &requirements);
      memory_.push_back(context.allocate_device_local(requirements, "allocating a lightmap page image"));
      check(vkBindImageMemory(d, image.image, memory_.back(), 0), "vkBindImageMemory");
      VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
      view.image = image.image;
      view.viewType = VK_IMAGE_VIEW_TYPE_2D;
      view.format = kFormat;
      view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
      check(vkCreateImageView(d, &view, nullptr, &images_.pages.back().view), "vkCreateImageView (a lightmap page)");
    }
    if (context.timeline_semaphores()) {
      VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
      type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
      VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      info.pNext = &type;
      check(vkCreateSemaphore(d, &info, nullptr, &images_.ready), "vkCreateSemaphore (page images ready)");
    }
  } catch (...) {
    release();
    throw;
  }
}

LightmapPageImages::~LightmapPageImages() { release(); }

void LightmapPageImages::release() {
  if (context_.hung()) return;  // a running submission may still use them (Context::cleanup)
  VkDevice d = context_.device();
  for (DevicePageImage& image : images_.pages) {
    if (image.view) vkDestroyImageView(d, std::exchange(image.view, VK_NULL_HANDLE), nullptr);
    if (image.image) vkDestroyImage(d, std::exchange(image.image, VK_NULL_HANDLE), nullptr);
  }
  for (VkDeviceMemory& memory : memory_)
    if (memory) vkFreeMemory(d, std::exchange(memory, VK_NULL_HANDLE), nullptr);
  if (images_.ready) vkDestroySemaphore(d, std::exchange(images_.ready, VK_NULL_HANDLE), nullptr);
}

bool LightmapPageImages::fits(const TexelGBuffer& gbuffer, int dilation_texels) const {
  if (gbuffer.texels.size() != texels_ || dilation_texels != dilation_ || gbuffer.pages.size() != images_.pages.size())
    return false;
  for (size_t p = 0; p < gbuffer.pages.size(); ++p)
    if (uint32_t(gbuffer.pages[p].width) != images_.pages[p].width || uint32_t(gbuffer.pages[p].height) != images_.pages[p].height)
      return false;
  return true;
}

const DevicePageImages& LightmapPageImages::write(const DeviceLightmap& lightmap) {
  if (lightmap.texels != texels_)
    throw std::logic_error("LightmapPageImages::write: the estimate has " + std::to_string(lightmap.texels) +
                           " texels, the pages " + std::to_string(texels_));
  if (images_.pages.empty()) return images_;
  VkDevice d = context_.device();
  for (size_t p = 0; p < images_.pages.size(); ++p) {
    const VkDescriptorBufferInfo buffers[3] = {{lightmap.sums.sums.handle(), 0, VK_WHOLE_SIZE},
                                               {lightmap.sums.samples.handle(), 0, VK_WHOLE_SIZE},
                                               {pixels_.handle(), 0, VK_WHOLE_SIZE}};
    const VkDescriptorImageInfo image{VK_NULL_HANDLE, images_.pages[p].view, VK_IMAGE_LAYOUT_GENERAL};
    VkWriteDescriptorSet writes[4]{};
    for (uint32_t b = 0; b < 4; ++b) {
      writes[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      writes[b].dstSet = kernel_.set(uint32_t(p));
      writes[b].dstBinding = b;
      writes[b].descriptorCount = 1;
      writes[b].descriptorType = b < 3 ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
      if (b < 3) writes[b].pBufferInfo = &buffers[b];
      else writes[b].pImageInfo = &image;
    }
    vkUpdateDescriptorSets(d, 4, writes, 0, nullptr);
  }
  VkCommandBuffer cmd = context_.begin();
  // After everything submitted to the queue before (an engine's draws reading the images, the
  // publish writing the estimate): their reads and writes done before the images are written.
  std::vector<VkImageMemoryBarrier> to_general;
  for (const DevicePageImage& page : images_.pages) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    b.oldLayout = initialized_ ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = page.image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    to_general.push_back(b);
  }
  VkMemoryBarrier buffers{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  buffers.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  buffers.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &buffers, 0,
                       nullptr, uint32_t(to_general.size()), to_general.data());
  for (size_t p = 0; p < images_.pages.size(); ++p) {
    const DevicePageImage& page = images_.pages[p];
    kernel_.bind(cmd, uint32_t(p));
    for (uint32_t ring = 0; ring <= rings_[p]; ++ring) {
      if (ring > 0) {  // ring k reads what rings below it wrote
        VkImageMemoryBarrier b = to_general[p];
        b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
        b.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0,
                             nullptr, 1, &b);
      }
      const PageImagesPush push{page.width, page.height, first_pixel_[p], ring};
      kernel_.push(cmd, &push, sizeof(push));
      vkCmdDispatch(cmd, (page.width + 7) / 8, (page.height + 7) / 8, 1);
    }
  }
  // Visible to whatever reads them next on this queue (an engine's fragment shaders, a copy).
  VkMemoryBarrier done{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  done.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  done.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &done, 0, nullptr, 0,
                       nullptr);
  if (images_.ready) context_.submit_and_wait(cmd, images_.ready, images_.ready_value + 1);
  else context_.submit_and_wait(cmd);
  if (images_.ready) ++images_.ready_value;
  initialized_ = true;
  return images_;
}

std::vector<float> LightmapPageImages::read_back(size_t page) {
  const DevicePageImage& image = images_.pages.at(page);
  const size_t floats = size_t(image.width) * image.height * 4;
  Buffer staging = context_.create_buffer(floats * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  VkCommandBuffer cmd = context_.begin();
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {image.width, image.height, 1};
  vkCmdCopyImageToBuffer(cmd, image.image, VK_IMAGE_LAYOUT_GENERAL, staging.handle(), 1, &region);
  VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0, nullptr);
  context_.submit_and_wait(cmd);
  std::vector<float> pixels(floats);
  std::memcpy(pixels.data(), staging.mapped(), floats * 4);
  return pixels;
}

}  // namespace exitance::vulkan
