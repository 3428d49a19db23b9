#pragma once
// One Vulkan instance, device and compute queue for the engine's compute
// passes. Create() returns null with a reason where no device can be had (no
// loader, no driver, no match for the requested name): callers and tests fall
// back to the CPU or skip, they do not crash. Every later failure throws
// GpuError naming the Vulkan call.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan_core.h>

#include "engine/gpu/device_choice.h"

namespace engine::gpu {

// Which mappable memory a mapped storage buffer (GpuBuffer::Placement::Mapped)
// takes. The CPU writes a frame's inputs into such buffers and reads the
// results back from them, so the choice is about the CPU's side:
// - Cached: host memory the CPU caches. Reads of results run at memory
//   speed; a discrete GPU reads and writes it over PCIe. The default.
// - WriteCombined: uncached host memory. Cheap CPU writes, but every CPU read
//   crosses the bus uncached (on an H100, a 640 x 360 frame's G-buffer took
//   26.6 ms instead of 5 ms).
// - Bar: device-local memory mapped through the PCIe BAR. Kernels read it at
//   the device's bandwidth, but every CPU access is uncached over PCIe (the
//   same frame took 924 ms).
// Where a device has only one kind (lavapipe, integrated GPUs) all three are
// the same memory. ENGINE_GPU_MEMORY=cached|write-combined|bar overrides.
enum class BufferMemory { Cached, WriteCombined, Bar };

struct GpuOptions {
  // Substring of the device name; empty: the ENGINE_GPU_DEVICE environment
  // variable, then the ranked default (device_choice.h).
  std::string device;
  // Khronos validation layer where installed. Default: on in debug builds,
  // where it costs nothing that matters; off in release, where it would slow
  // every call.
#ifdef NDEBUG
  bool validation = false;
#else
  bool validation = true;
#endif
  BufferMemory buffer_memory = BufferMemory::Cached;
  // DeviceOnly buffers that landed in mappable memory are written directly.
  // True: always through staging copies, so tests on lavapipe take the path
  // a discrete GPU takes.
  bool stage_device_only = false;
  // Caps DeviceInfo::max_storage_buffer_range below the device's (0 = no
  // cap), so tests reach the path a device too small for a scene takes.
  std::uint64_t storage_buffer_range_cap = 0;
  // Trace with VK_KHR_ray_query (acceleration structures the driver builds
  // and traverses, on RT cores where the GPU has them) where the device has
  // it; false: the compute-shader BVH traversal everywhere.
  // ENGINE_GPU_RAY_QUERY=off turns it off for A/B runs (on: as asked here).
  bool ray_query = true;
  // The camera's hits from a raster visibility pass (VisibilityPass) where
  // the queue can rasterise, instead of the camera rays traced: no camera
  // rays cross the bus and the GPU's rasteriser finds them. A sample that
  // falls exactly on an edge may go to the other surface than a ray's edge
  // test gives it (the top-left rule), so the frame equals the CPU
  // backend's except at such pixels (docs/gpu.md).
  // ENGINE_GPU_RASTER_VISIBILITY=on|off sets it for A/B runs.
  bool raster_visibility = true;
  // For a window that presents on the kernels' device: instance extensions
  // to enable (GLFW's surface extensions), device extensions to enable
  // (VK_KHR_swapchain), and a test the queue family must pass besides
  // compute (graphics, and presentation to the window). Empty and null:
  // a compute queue, nothing more.
  std::vector<const char*> instance_extensions, device_extensions;
  std::function<bool(VkInstance, VkPhysicalDevice, std::uint32_t family)> queue_family_accepts;
};

// The VK_KHR_acceleration_structure entry points, which the loader does not
// export: looked up once per device (null where ray queries are off).
struct AccelerationStructureApi {
  PFN_vkCreateAccelerationStructureKHR create = nullptr;
  PFN_vkDestroyAccelerationStructureKHR destroy = nullptr;
  PFN_vkGetAccelerationStructureBuildSizesKHR build_sizes = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR cmd_build = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR device_address = nullptr;
};

struct DeviceInfo {
  std::string name;
  DeviceKind kind = DeviceKind::Other;
  std::string driver;       // "llvmpipe Mesa 22.3.6 (LLVM 15.0.6)"
  bool shader_float16 = false;
  bool shader_int64 = false;  // the shading kernels need it (shaders/pcg32.glsl)
  std::uint32_t max_shared_memory = 0;
  std::uint64_t max_storage_buffer_range = 0;  // the largest buffer a kernel can bind
  double timestamp_period_ns = 0;  // 0: the queue has no timestamps
  BufferMemory buffer_memory = BufferMemory::Cached;
  // Largest heap of mappable device-local memory, 0 where there is none
  // (a discrete GPU without resizable BAR exposes 256 MB).
  std::uint64_t mappable_device_local_bytes = 0;
  bool stage_device_only = false;  // GpuOptions::stage_device_only
  // Rays are traced with VK_KHR_ray_query: the device has it (with
  // acceleration structures and buffer device addresses) and
  // GpuOptions::ray_query asked for it.
  bool ray_query = false;
  // The queue the context submits to supports graphics (a raster pass).
  bool graphics_queue = false;
  // The camera's hits come from the raster visibility pass: asked for
  // (GpuOptions::raster_visibility) and graphics_queue.
  bool raster_visibility = false;
  std::uint32_t scratch_alignment = 0;  // minAccelerationStructureScratchOffsetAlignment
};

// The memory types of `mem` among `type_bits` a storage buffer may take, best
// first: mapped ones (host-visible and coherent) in `preference`'s order,
// device-only ones device-local first (VulkanContext::buffer_memory_types on
// its device's memory; here for tests with made-up devices).
std::vector<std::uint32_t> rank_buffer_memory_types(const VkPhysicalDeviceMemoryProperties& mem, std::uint32_t type_bits,
                                                    bool mapped, BufferMemory preference);

// "vulkan (NAME; DRIVER; buffers: ...)" for logs and benchmark output.
std::string describe(const DeviceInfo& info);

// What crossed between host and device, counted where it happens (issue 36:
// counted, not assumed): command buffers submitted; bytes the host wrote to
// and read from buffers. A mapped buffer's bytes count when the host takes a
// span of them (GpuBuffer::mapped_as: a span of const T is read, any other
// written), so a span taken but only partly touched still counts whole: an
// upper bound. upload() and download() count what they copy.
struct GpuTraffic {
  std::uint64_t submissions = 0, host_to_device_bytes = 0, device_to_host_bytes = 0;
  [[nodiscard]] GpuTraffic operator-(const GpuTraffic& o) const {
    return {submissions - o.submissions, host_to_device_bytes - o.host_to_device_bytes,
            device_to_host_bytes - o.device_to_host_bytes};
  }
};

// A Vulkan device the host engine made and keeps (as the RTXGI SDK runs on
// its host's device). The context records and submits on `queue` and never
// destroys what it did not create; the host must not submit to that queue
// from another thread while the context's work runs, and destroys the
// device after the context. The kernels need shaderInt64 enabled (the
// shading kernels draw Pcg32's numbers bit for bit); float16 is used where
// enabled, and rays are traced with VK_KHR_ray_query where the host enabled
// VK_KHR_acceleration_structure, VK_KHR_ray_query and
// VK_KHR_deferred_host_operations with their features and
// bufferDeviceAddress, else by the compute-shader BVH traversal.
struct HostVulkanDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;  // must support compute
  bool enabled_shader_int64 = false;
  bool enabled_shader_float16 = false;
  bool enabled_ray_query = false;
};

struct DeviceFeatures;

class VulkanContext {
 public:
  // Null and *why_not set when no usable device exists.
  static std::unique_ptr<VulkanContext> create(const GpuOptions& options, std::string* why_not);
  // On the host's device (HostVulkanDevice); null and *why_not set when it
  // cannot serve (no compute on the queue's family, a handle missing).
  // options.device is ignored: the host chose the device.
  static std::unique_ptr<VulkanContext> adopt(const HostVulkanDevice& host, const GpuOptions& options, std::string* why_not);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  [[nodiscard]] VkDevice device() const { return device_; }
  [[nodiscard]] VkPhysicalDevice physical_device() const { return physical_; }
  [[nodiscard]] VkInstance instance() const { return instance_; }
  // The one queue the context submits to, and its family: a host that
  // presents on it submits from the thread that runs the kernels.
  [[nodiscard]] VkQueue queue() const { return queue_; }
  [[nodiscard]] std::uint32_t queue_family() const { return queue_family_; }
  [[nodiscard]] const DeviceInfo& info() const { return info_; }
  // Valid where info().ray_query.
  [[nodiscard]] const AccelerationStructureApi& acceleration_structures() const { return as_api_; }
  // Validation-layer errors seen so far (0 without the layer); tests assert 0.
  [[nodiscard]] int validation_errors() const { return validation_errors_; }
  [[nodiscard]] bool validation_enabled() const { return messenger_ != VK_NULL_HANDLE; }

  // A memory type with these property flags among `type_bits`; throws
  // GpuError if there is none.
  [[nodiscard]] std::uint32_t memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags flags) const;
  // Memory types for a storage buffer among `type_bits`, best first (GpuBuffer
  // tries them in order): mapped ones are host-visible and coherent, ranked
  // by info().buffer_memory; device-only ones are device-local first.
  [[nodiscard]] std::vector<std::uint32_t> buffer_memory_types(std::uint32_t type_bits, bool mapped) const;

  // Records commands with `record`, submits them, waits. Returns the GPU
  // time between the first and last command in milliseconds (timestamps), or
  // -1 where the queue has none.
  double submit_and_wait(const std::function<void(VkCommandBuffer)>& record);
  // Inside submit_and_wait's `record`: ends a stage of the submission here
  // (a timestamp once the commands recorded so far are done), so that one
  // submission of several stages still times each. Ignored past
  // kMaxStageMarks marks, or where the queue has no timestamps.
  void mark_stage(VkCommandBuffer cmd);
  // The last submission's stage times in milliseconds: one per mark_stage,
  // then one for the commands after the last mark; they sum to its total.
  // Empty where the queue has no timestamps.
  [[nodiscard]] const std::vector<double>& last_stage_ms() const { return last_stage_ms_; }
  static constexpr std::uint32_t kMaxStageMarks = 30;

  // Commands whose results the host does not wait for (a TLAS rebuilt for
  // the next traces, a query read later): recorded at the head of the next
  // submission, whoever makes it, so that they cost no submission of their
  // own (issue 36: one submission a frame). A barrier separates them from
  // that submission's own commands, whose stage times and total exclude
  // them; their device time is kept for `owner` (take_deferred_ms). An
  // owner that frees what its recordings use first calls forget_deferred
  // (its destructor) or flush (before it replaces a buffer they read).
  void record_before_next(const void* owner, std::function<void(VkCommandBuffer)> record);
  // Submits what record_before_next queued, alone, and waits; nothing
  // where nothing is queued.
  void flush();
  // Whether `owner` has commands queued.
  [[nodiscard]] bool has_deferred(const void* owner) const;
  void forget_deferred(const void* owner);
  // Device milliseconds of `owner`'s queued commands that ran since the
  // last call.
  double take_deferred_ms(const void* owner);

  // The traffic since the context was made (thread-safe); a frame's is the
  // difference of two readings.
  [[nodiscard]] GpuTraffic traffic() const {
    return {submissions_.load(std::memory_order_relaxed), host_to_device_.load(std::memory_order_relaxed),
            device_to_host_.load(std::memory_order_relaxed)};
  }
  void count_host_to_device(std::uint64_t bytes) { host_to_device_.fetch_add(bytes, std::memory_order_relaxed); }
  void count_device_to_host(std::uint64_t bytes) { device_to_host_.fetch_add(bytes, std::memory_order_relaxed); }

 private:
  VulkanContext() = default;
  // info_ from the physical device, the options and the environment's
  // overrides; an error message, or empty.
  std::string describe_device(const GpuOptions& options, const DeviceFeatures& features, bool ray_query_enabled);
  // The ray-query entry points, command pool and buffer, fence and
  // timestamp queries on device_ and queue_family_; an error message, or empty.
  std::string make_submission_objects(const VkPhysicalDeviceProperties& props);
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                      VkDebugUtilsMessageTypeFlagsEXT,
                                                      const VkDebugUtilsMessengerCallbackDataEXT* data, void* self);

  bool owns_device_ = true;  // false: adopted from the host, which destroys it
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkQueryPool timestamps_ = VK_NULL_HANDLE;
  DeviceInfo info_;
  AccelerationStructureApi as_api_;
  int validation_errors_ = 0;
  std::atomic<std::uint64_t> submissions_{0}, host_to_device_{0}, device_to_host_{0};
  std::uint32_t marks_ = 0;  // stage marks recorded in the submission being recorded
  struct Deferred {
    const void* owner;
    std::function<void(VkCommandBuffer)> record;
  };
  std::vector<Deferred> deferred_;
  std::vector<std::pair<const void*, double>> deferred_ms_;  // by owner
  // Records the queued commands at the head of `cmd` with a timestamp after
  // each (their owners' times come from marks 1..n); returns n.
  std::uint32_t record_deferred(VkCommandBuffer cmd, std::vector<const void*>& owners);
  std::vector<double> last_stage_ms_;
};

}  // namespace engine::gpu
