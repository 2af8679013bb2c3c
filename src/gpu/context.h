#pragma once
/// The Vulkan base shared by the simulation and the renderer: instance, device, one queue, a
/// command pool, buffers, one-shot submissions, validation with a message counter.
///
/// How the renderer uses it: fill ContextOptions with `graphics = true`, the surface instance
/// extensions (VK_KHR_surface + the platform one, e.g. from glfwGetRequiredInstanceExtensions)
/// and the device extension VK_KHR_swapchain, call VulkanContext::create(), create its surface
/// from `instance()`, then build a GpuSolver on the same context (`GpuSolver(ctx)`). Solver and
/// renderer share `queue()`: the solver's submissions end with a barrier from compute to every
/// later command (computeToAll in barriers.h), so a frame submitted after a tick reads the
/// solver's buffers (pos, normal, uv, triangles, counters.draw_args) directly, with no copy. The
/// renderer draws with render passes; Vulkan 1.3 synchronization2 is enabled on the device.
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <vulkan/vulkan.h>

#include "spirv_rules.h"

namespace tender::gpu {

/// A Vulkan call failed at run time: what() is one line for the user ("Vulkan error
/// VK_ERROR_DEVICE_LOST in vkQueueSubmit2"); the programs end with it as `tender: error: ...` and
/// exit status 2.
class VulkanError : public std::runtime_error {
public:
  VulkanError(VkResult result, const std::string& message) : std::runtime_error(message), result_(result) {}
  /// The failed call's result.
  VkResult result() const { return result_; }

private:
  VkResult result_;
};

/// Throws VulkanError for a failed call; the file and line go to stderr only with TENDER_DEBUG set.
[[noreturn]] void vkCheckFailed(VkResult result, const char* expr, const char* file, int line);
/// Name of a VkResult ("VK_ERROR_DEVICE_LOST").
std::string vkResultName(VkResult result);

/// Checks a Vulkan call in every build type (Release too); a failure throws VulkanError.
#define VK_CHECK(expr)                                                                                                 \
  do {                                                                                                                 \
    VkResult vk_check_result_ = (expr);                                                                                \
    if (vk_check_result_ != VK_SUCCESS) ::tender::gpu::vkCheckFailed(vk_check_result_, #expr, __FILE__, __LINE__);     \
  } while (0)

/// A value or a one-line error message (C++20 has no std::expected).
template <class T>
class Result {
public:
  /// A success holding `value`.
  Result(T value) : v_(std::move(value)) {}
  /// A failure with a one-line message.
  static Result failure(std::string message) {
    Result r;
    r.v_ = Error{std::move(message)};
    return r;
  }
  /// True on success.
  explicit operator bool() const { return std::holds_alternative<T>(v_); }
  /// The value (success only).
  T& value() { return std::get<T>(v_); }
  T& operator*() { return value(); }
  T* operator->() { return &value(); }
  /// The message (failure only).
  const std::string& error() const { return std::get<Error>(v_).message; }

private:
  struct Error {
    std::string message;
  };
  Result() = default;
  std::variant<Error, T> v_;
};

/// How to create the context.
struct ContextOptions {
  int device = -1;                              ///< index as `tender devices` lists; -1 = prefer discrete
  bool validation = false;                      ///< VK_LAYER_KHRONOS_validation
  bool sync_validation = true;                  ///< with validation: synchronization validation too
  bool graphics = false;                        ///< the queue must support graphics as well as compute
  bool quiet = false;                           ///< do not print validation messages (still counted)
  std::vector<std::string> instance_extensions; ///< e.g. VK_KHR_surface for the renderer
  std::vector<std::string> device_extensions;   ///< e.g. VK_KHR_swapchain for the renderer
};

/// One physical device as `tender devices` shows it.
struct DeviceInfo {
  uint32_t index = 0; ///< enumeration order (the --device value)
  std::string name;
  std::string type;          ///< "discrete", "integrated", "virtual", "cpu", "other"
  std::string driver;        ///< driver name and info
  uint64_t memory_bytes = 0; ///< largest device-local heap
  uint32_t api_version = 0;
  bool usable = false;        ///< Vulkan 1.3 with a compute queue
  FloatControls floats;       ///< the 32-bit float controls it can be asked for
  uint32_t subgroup_size = 0; ///< invocations per subgroup
  uint32_t shared_memory = 0; ///< bytes of shared memory per workgroup
  uint32_t preference = 0;    ///< a context given no index takes the usable device that comes first here
};

/// Lists the Vulkan devices, or fails with one line when Vulkan or a device is missing.
Result<std::vector<DeviceInfo>> listDevices();

/// `count` descriptor sets of `layout` from `pool` (throws VulkanError when Vulkan fails).
std::vector<VkDescriptorSet> allocateDescriptorSets(VkDevice dev, VkDescriptorPool pool, VkDescriptorSetLayout layout,
                                                    uint32_t count);

/// A buffer with its own memory; `mapped` is set for host-visible buffers.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  void* mapped = nullptr;
};

/// Instance, device, queue, command pool and helpers. Not copyable; destroy after every user.
class VulkanContext {
public:
  /// Creates the context; fails with one line (no device, no Vulkan 1.3, missing layer).
  static Result<std::unique_ptr<VulkanContext>> create(const ContextOptions& options);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queue_family_; }
  /// Command pool of the queue family (command buffers may be reset individually).
  VkCommandPool commandPool() const { return pool_; }
  /// Nanoseconds per timestamp tick.
  double timestampPeriod() const { return timestamp_period_; }
  /// True when the queue supports timestamps.
  bool timestampsSupported() const { return timestamp_bits_ > 0; }
  const VkPhysicalDeviceProperties& properties() const { return props_; }
  /// The chosen device as `tender devices` describes it.
  const DeviceInfo& info() const { return info_; }
  /// The 32-bit float controls the device can be asked for.
  const FloatControls& floatControls() const { return info_.floats; }
  /// The float rules of the simulation's shaders on this device: `decide`'s, asked once a context
  /// (gpu::simFloatRules, which runs a probe on a CPU device) and shared by its solvers and fleets.
  FloatRules floatRules(const std::function<FloatRules()>& decide);
  /// Validation warnings and errors reported so far (0 without validation).
  uint32_t validationMessages() const { return validation_messages_.load(); }
  bool validationEnabled() const { return validation_; }

  /// The pipeline `name` names, made by `make` (which sets the shader module to destroy with it)
  /// the first time it is asked for: the simulation's pipelines, which every solver and fleet on
  /// this context shares (sim_pipeline.h, SimLayout), live until the context does. Thread-safe:
  /// pipelines of different names are made side by side.
  VkPipeline sharedPipeline(const std::string& name, const std::function<VkPipeline(VkShaderModule&)>& make);

  /// Creates a buffer in device-local memory.
  Buffer createDeviceBuffer(VkDeviceSize size, VkBufferUsageFlags usage);
  /// Creates a persistently mapped host-visible, host-coherent buffer.
  Buffer createHostBuffer(VkDeviceSize size, VkBufferUsageFlags usage);
  /// True when buffers can be reached by device address (bufferDeviceAddress and shaderInt64: a
  /// fleet's batched tick needs both).
  bool deviceAddresses() const { return device_addresses_; }
  /// The device address of a buffer created with VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT.
  VkDeviceAddress address(const Buffer& b) const;
  /// Destroys a buffer and frees its memory (no-op on an empty one).
  void destroyBuffer(Buffer& b);
  /// Copies bytes out of a device buffer through a staging buffer (waits for completion).
  void download(const Buffer& src, void* data, VkDeviceSize size, VkDeviceSize offset = 0);
  /// Records commands into a fresh command buffer, submits, and waits for the queue to finish them.
  void submitOnce(const std::function<void(VkCommandBuffer)>& record);
  /// Resets `fence` and submits one recorded command buffer that signals it.
  void submit(VkCommandBuffer cmd, VkFence fence) const;
  /// Waits until the queue is idle.
  void waitIdle();
  /// Memory type index with these properties, or UINT32_MAX.
  uint32_t findMemoryType(uint32_t type_bits, VkMemoryPropertyFlags flags) const;

private:
  VulkanContext() = default;
  /// The steps of create(); each gives an error message, or nothing when done.
  std::optional<std::string> createInstance(const ContextOptions& o);
  std::optional<std::string> choosePhysicalDevice(const ContextOptions& o);
  std::optional<std::string> createDevice(const ContextOptions& o);
  Buffer createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags flags, bool map);
  static VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                      VkDebugUtilsMessageTypeFlagsEXT types,
                                                      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence once_fence_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties props_{};
  VkPhysicalDeviceMemoryProperties mem_props_{};
  DeviceInfo info_;
  double timestamp_period_ = 1.0;
  uint32_t timestamp_bits_ = 0;
  bool validation_ = false, quiet_ = false;
  bool device_addresses_ = false;
  std::atomic<uint32_t> validation_messages_{0};
  std::once_flag float_rules_once_;
  FloatRules float_rules_; ///< floatRules'
  std::mutex pipelines_mutex_;
  std::map<std::string, std::pair<VkPipeline, VkShaderModule>> pipelines_; ///< sharedPipeline's
};

/// Sets VK_DRIVER_FILES to lavapipe when it is unset (tests: results independent of the machine).
void preferLavapipeForTests();

} // namespace tender::gpu
