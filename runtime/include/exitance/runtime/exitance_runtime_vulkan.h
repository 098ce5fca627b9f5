/* Exitance runtime, Vulkan interop (C99): the runtime on an engine's own Vulkan device, and the
 * lightmap pages it publishes as device images the engine samples, with the semaphore to wait on
 * (docs/runtime.md, "Results on the device"), and its light probes and voxel exitance as device buffers.
 * samples/engine_sample renders a scene with the pages.
 *
 *   ExitanceRuntimeVulkanDevice device = {instance, physical, vk_device, queue, family,
 *                                         VK_API_VERSION_1_2, enabled_features, 1};
 *   exitance_runtime_open_on_device("scene.bake", NULL, &device, &rt);
 *   ...
 *   exitance_runtime_refresh(rt, 16.0, 0, NULL);
 *   ExitanceRuntimePageImage pages[8];
 *   ExitanceRuntimeImagesReady ready;
 *   exitance_runtime_publish_page_images(rt, pages, 8, &ready);
 *   // submit the frame waiting on ready.semaphore >= ready.value (VkTimelineSemaphoreSubmitInfo),
 *   // sampling pages[p].view in layout pages[p].layout
 */
#ifndef EXITANCE_RUNTIME_VULKAN_H
#define EXITANCE_RUNTIME_VULKAN_H

#include <vulkan/vulkan.h>

#include "exitance_runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/* An engine's device, adopted by the runtime (it creates no instance or device and destroys none).
 * The engine keeps them alive until exitance_runtime_release, and does not use `queue` from
 * another thread during a runtime call (vkQueueSubmit needs the queue externally synchronised). */
typedef struct ExitanceRuntimeVulkanDevice {
  VkInstance instance;
  VkPhysicalDevice physical_device;
  VkDevice device;
  VkQueue queue;         /* of `queue_family`, which supports compute; the runtime submits here */
  uint32_t queue_family;
  uint32_t api_version;  /* VkApplicationInfo::apiVersion of the instance: 1.2 or later */
  VkPhysicalDeviceFeatures enabled_features; /* what the device was created with: shaderInt64, shaderFloat64 at least */
  int32_t timeline_semaphore; /* 1: created with VkPhysicalDeviceVulkan12Features::timelineSemaphore */
} ExitanceRuntimeVulkanDevice;

/* exitance_runtime_open on the engine's device. options->device_index must be -1 (the device is
 * the engine's); a device that lacks what the runtime needs is EXITANCE_RUNTIME_NO_DEVICE naming it. */
ExitanceRuntimeError exitance_runtime_open_on_device(const char* bundle, const ExitanceRuntimeOptions* options,
                                                     const ExitanceRuntimeVulkanDevice* device,
                                                     ExitanceRuntime** out_runtime);

/* The device the runtime runs on: the adopted one, or the one it created (whose queue family
 * supports compute; an engine rendering on it checks the family for graphics itself). */
ExitanceRuntimeError exitance_runtime_vulkan_device(const ExitanceRuntime* runtime, ExitanceRuntimeVulkanDevice* out_device);

/* One lightmap page in device memory. */
typedef struct ExitanceRuntimePageImage {
  VkImage image;
  VkImageView view;     /* 2D, the whole image */
  VkFormat format;      /* VK_FORMAT_R32G32B32A32_SFLOAT: E/pi in R, G, B; the texel coverage in A */
  VkImageLayout layout; /* VK_IMAGE_LAYOUT_GENERAL, always: sample it in this layout */
  uint32_t width;
  uint32_t height;
} ExitanceRuntimePageImage;

/* When the images may be read. */
typedef struct ExitanceRuntimeImagesReady {
  VkSemaphore semaphore; /* timeline semaphore; VK_NULL_HANDLE on a device without timeline semaphores */
  uint64_t value;        /* wait until the semaphore reaches it before reading the images */
  uint32_t queue_family; /* the family the runtime writes them on; the images are shared by every
                            family of the device (VK_SHARING_MODE_CONCURRENT): no ownership transfer */
} ExitanceRuntimeImagesReady;

/* Writes what the runtime publishes now into one device image per page (the values read_page
 * returns: E/pi, gutters dilated the same way; at open the bundle's baked lightmap when it was baked
 * with at least 16 samples per texel, else 0 until refreshed) and describes them in
 * out_images[0 .. page_count-1];
 * image_count must be at least exitance_runtime_page_count. The images and views are the same on
 * every call and valid until exitance_runtime_release; only this call writes them, on the
 * runtime's queue, after every command submitted to that queue before it (so an engine's reads
 * submitted to the same queue finish first; reads on another queue must be finished by the
 * engine). No host read-back. out_ready may be NULL. */
ExitanceRuntimeError exitance_runtime_publish_page_images(ExitanceRuntime* runtime, ExitanceRuntimePageImage* out_images,
                                                          uint32_t image_count, ExitanceRuntimeImagesReady* out_ready);

/* The light probes as they show now, in device memory (docs/runtime.md "Probes"). */
typedef struct ExitanceRuntimeProbeBuffer {
  VkBuffer buffer;      /* 27 floats per probe of the bundle's grid, in probes.bin's order: the L2 SH of
                           incident radiance, coefficient i, channel c at [i * 3 + c]; 0 for probes not in use */
  VkDeviceSize size;    /* bytes (108 per probe) */
  uint32_t probe_count; /* the grid's probes (exitance_runtime_probe_count) */
} ExitanceRuntimeProbeBuffer;

/* Writes what the probes show now (the values exitance_runtime_read_probes returns, bit for bit)
 * into a device buffer and describes it in *out_buffer. The buffer is the same on every call and
 * valid until exitance_runtime_release; only this call writes it, on the runtime's queue, after
 * every command submitted to that queue before it; it is shared by every queue family of the device
 * (VK_SHARING_MODE_CONCURRENT). Wait for out_ready (may be NULL) as for the page images. No host
 * read-back. A bundle without probes, or a runtime that does not refresh them:
 * EXITANCE_RUNTIME_INVALID_ARGUMENT, nothing changed. */
ExitanceRuntimeError exitance_runtime_publish_probes(ExitanceRuntime* runtime, ExitanceRuntimeProbeBuffer* out_buffer,
                                                     ExitanceRuntimeImagesReady* out_ready);

/* The voxel exitance of what the runtime shows now, in device memory (docs/runtime.md "Voxel exitance"). */
typedef struct ExitanceRuntimeVoxelBuffer {
  VkBuffer buffer;      /* 6 floats per node of the bundle's svo.bin, in its order: front RGB, back RGB,
                           M = pi L_o in W/m^2 scene units (exitance_runtime_read_voxel_exitance's
                           values before their half-float encoding) */
  VkDeviceSize size;    /* bytes (24 per node) */
  uint32_t node_count;  /* exitance_runtime_voxel_count */
} ExitanceRuntimeVoxelBuffer;

/* Computes the voxel exitance on the device from what the runtime shows (filtered where a denoise
 * radius is set) into a device buffer and describes it in *out_buffer: the same buffer on every call,
 * valid until exitance_runtime_release, written only by this call on the runtime's queue after
 * everything submitted to it before, shared by every queue family; wait for out_ready (may be NULL)
 * as for the page images. No host read-back (after an edit that moved texels or changed materials,
 * the next call works out on the host where texels deposit: ~0.1 s at 1 M texels). A bundle without
 * svo.bin: EXITANCE_RUNTIME_INVALID_ARGUMENT, nothing changed. */
ExitanceRuntimeError exitance_runtime_publish_voxel_exitance(ExitanceRuntime* runtime, ExitanceRuntimeVoxelBuffer* out_buffer,
                                                             ExitanceRuntimeImagesReady* out_ready);

#ifdef __cplusplus
}
#endif

#endif /* EXITANCE_RUNTIME_VULKAN_H */
