#include "context.h"

#include "barriers.h"
#include "core/denormal_mode.h"

#include <algorithm>
#include <cstring>

#include <vulkan/vulkan.hpp>
#include <vulkan/vulkan_to_string.hpp>

namespace tender::gpu {

std::string vkResultName(VkResult result) { return vk::to_string(vk::Result(result)); }

void vkCheckFailed(VkResult result, const char* expr, const char* file, int line) {
  std::string call(expr);
  call = call.substr(0, call.find('('));
  if (std::getenv("TENDER_DEBUG")) std::fprintf(stderr, "tender: debug: %s failed at %s:%d\n", expr, file, line);
  throw VulkanError(result, "Vulkan error " + vkResultName(result) + " in " + call);
}

void preferLavapipeForTests() {
  if (!std::getenv("VK_DRIVER_FILES") && !std::getenv("VK_ICD_FILENAMES"))
    setenv("VK_DRIVER_FILES", "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json", 0);
}

namespace {

const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

const char* typeName(VkPhysicalDeviceType t) {
  switch (t) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
    return "discrete";
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
    return "integrated";
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
    return "virtual";
  case VK_PHYSICAL_DEVICE_TYPE_CPU:
    return "cpu";
  default:
    return "other";
  }
}

// Preference of a device type when no index is given: discrete first, CPU last.
int typeRank(VkPhysicalDeviceType t) {
  switch (t) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
    return 0;
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
    return 1;
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
    return 2;
  case VK_PHYSICAL_DEVICE_TYPE_CPU:
    return 3;
  default:
    return 4;
  }
}

// Queue family with compute (and graphics when asked), preferring one that has timestamps.
std::optional<uint32_t> findQueueFamily(VkPhysicalDevice pd, bool graphics) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> fams(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, fams.data());
  std::optional<uint32_t> best;
  for (uint32_t i = 0; i < n; ++i) {
    VkQueueFlags need = VK_QUEUE_COMPUTE_BIT | (graphics ? VK_QUEUE_GRAPHICS_BIT : 0);
    if ((fams[i].queueFlags & need) != need) continue;
    if (!best || (fams[*best].timestampValidBits == 0 && fams[i].timestampValidBits > 0)) best = i;
  }
  return best;
}

DeviceInfo describe(VkPhysicalDevice pd, uint32_t index) {
  VkPhysicalDeviceProperties basic{};
  vkGetPhysicalDeviceProperties(pd, &basic);
  // Float controls are core from Vulkan 1.2; older devices are listed but not usable
  VkPhysicalDeviceFloatControlsProperties floats{};
  floats.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FLOAT_CONTROLS_PROPERTIES;
  VkPhysicalDeviceSubgroupProperties subgroup{};
  subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
  subgroup.pNext = basic.apiVersion >= VK_API_VERSION_1_2 ? &floats : nullptr;
  VkPhysicalDeviceDriverProperties driver{};
  driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
  driver.pNext = &subgroup;
  VkPhysicalDeviceProperties2 props2{};
  props2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  props2.pNext = &driver;
  vkGetPhysicalDeviceProperties2(pd, &props2);
  const VkPhysicalDeviceProperties& p = props2.properties;
  VkPhysicalDeviceMemoryProperties mem{};
  vkGetPhysicalDeviceMemoryProperties(pd, &mem);
  DeviceInfo d;
  d.index = index;
  d.name = p.deviceName;
  d.preference = uint32_t(typeRank(p.deviceType));
  d.type = typeName(p.deviceType);
  d.driver = std::string(driver.driverName);
  if (driver.driverInfo[0]) d.driver += std::string(" ") + driver.driverInfo;
  for (uint32_t h = 0; h < mem.memoryHeapCount; ++h)
    if (mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      d.memory_bytes = std::max<uint64_t>(d.memory_bytes, mem.memoryHeaps[h].size);
  d.api_version = p.apiVersion;
  d.usable = p.apiVersion >= VK_API_VERSION_1_3 && findQueueFamily(pd, false).has_value();
  d.floats.rounding_rte = floats.shaderRoundingModeRTEFloat32;
  d.floats.denorm_preserve = floats.shaderDenormPreserveFloat32;
  d.floats.denorm_flush = floats.shaderDenormFlushToZeroFloat32;
  d.subgroup_size = subgroup.subgroupSize;
  d.shared_memory = p.limits.maxComputeSharedMemorySize;
  return d;
}

bool hasLayer(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  for (auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

bool hasInstanceExtension(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateInstanceExtensionProperties(nullptr, &n, exts.data());
  for (auto& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

bool hasDeviceExtension(VkPhysicalDevice pd, const std::string& name) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
  for (auto& e : exts)
    if (name == e.extensionName) return true;
  return false;
}

// A bare instance for enumeration; VK_NULL_HANDLE and a message when the loader finds nothing.
VkInstance createBareInstance(std::string& error) {
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "tender";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ci.pApplicationInfo = &app;
  VkInstance inst = VK_NULL_HANDLE;
  VkResult r = vkCreateInstance(&ci, nullptr, &inst);
  if (r != VK_SUCCESS) {
    error = "no Vulkan driver found (vkCreateInstance: " + vkResultName(r) + ")";
    return VK_NULL_HANDLE;
  }
  return inst;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance inst) {
  uint32_t n = 0;
  if (vkEnumeratePhysicalDevices(inst, &n, nullptr) != VK_SUCCESS) return {};
  std::vector<VkPhysicalDevice> pds(n);
  if (vkEnumeratePhysicalDevices(inst, &n, pds.data()) < 0) return {};
  pds.resize(n);
  return pds;
}

} // namespace

Result<std::vector<DeviceInfo>> listDevices() {
  std::string error;
  VkInstance inst = createBareInstance(error);
  if (!inst) return Result<std::vector<DeviceInfo>>::failure(error);
  std::vector<DeviceInfo> out;
  auto pds = physicalDevices(inst);
  for (uint32_t i = 0; i < pds.size(); ++i) out.push_back(describe(pds[i], i));
  vkDestroyInstance(inst, nullptr);
  if (out.empty()) return Result<std::vector<DeviceInfo>>::failure("no Vulkan device found");
  return out;
}

VKAPI_ATTR VkBool32 VKAPI_CALL VulkanContext::debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                            VkDebugUtilsMessageTypeFlagsEXT,
                                                            const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                            void* user) {
  auto* self = static_cast<VulkanContext*>(user);
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) return VK_FALSE;
  // Only the layers' messages count: the loader reports through the same messenger (for example
  // that VK_INSTANCE_LAYERS enabled a layer), and its notices are no validation findings.
  if (data && data->pMessageIdName && std::strcmp(data->pMessageIdName, "Loader Message") == 0) return VK_FALSE;
  self->validation_messages_.fetch_add(1);
  if (!self->quiet_)
    std::fprintf(stderr, "tender: validation %s: %s\n",
                 severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
                 data && data->pMessage ? data->pMessage : "(no message)");
  return VK_FALSE;
}

Result<std::unique_ptr<VulkanContext>> VulkanContext::create(const ContextOptions& o) {
  using R = Result<std::unique_ptr<VulkanContext>>;
  std::unique_ptr<VulkanContext> ctx(new VulkanContext());
  ctx->validation_ = o.validation;
  ctx->quiet_ = o.quiet;
  {
    // A thread starts with its creator's FTZ and DAZ (POSIX: the floating-point environment is
    // inherited), so the threads a CPU device (lavapipe) starts for its instance and device run
    // shaders with the CPU reference's denormal rules; gpu::simFloatRules proves it before it
    // relies on it. This thread's own mode is restored.
    const DenormalMode host_rules(true);
    if (auto err = ctx->createInstance(o)) return R::failure(*err);
    if (auto err = ctx->choosePhysicalDevice(o)) return R::failure(*err);
    if (auto err = ctx->createDevice(o)) return R::failure(*err);
  }
  VkCommandPoolCreateInfo pci{};
  pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = ctx->queue_family_;
  VK_CHECK(vkCreateCommandPool(ctx->device_, &pci, nullptr, &ctx->pool_));
  VkFenceCreateInfo fci{};
  fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VK_CHECK(vkCreateFence(ctx->device_, &fci, nullptr, &ctx->once_fence_));
  return R(std::move(ctx));
}

// Instance: layers, extensions, the debug messenger chained for creation-time messages.
std::optional<std::string> VulkanContext::createInstance(const ContextOptions& o) {
  std::vector<const char*> layers, inst_exts;
  for (auto& e : o.instance_extensions) inst_exts.push_back(e.c_str());
  if (o.validation) {
    if (!hasLayer(kValidationLayer)) return "validation requested but VK_LAYER_KHRONOS_validation is not installed";
    layers.push_back(kValidationLayer);
  }
  const bool debug_utils = o.validation && hasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  if (debug_utils) inst_exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  for (auto* e : inst_exts)
    if (std::strcmp(e, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) != 0 && !hasInstanceExtension(e))
      return std::string("Vulkan instance extension ") + e + " is not available";

  VkDebugUtilsMessengerCreateInfoEXT dbg{};
  dbg.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  dbg.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  dbg.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  dbg.pfnUserCallback = &VulkanContext::debugCallback;
  dbg.pUserData = this;

  VkValidationFeatureEnableEXT sync_feature = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{};
  features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &sync_feature;
  features.pNext = debug_utils ? &dbg : nullptr;

  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "tender";
  app.pEngineName = "tender";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = uint32_t(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = uint32_t(inst_exts.size());
  ici.ppEnabledExtensionNames = inst_exts.data();
  if (o.validation && o.sync_validation)
    ici.pNext = &features;
  else if (debug_utils)
    ici.pNext = &dbg;
  VkResult r = vkCreateInstance(&ici, nullptr, &instance_);
  if (r != VK_SUCCESS) {
    instance_ = VK_NULL_HANDLE;
    return "no Vulkan driver found (vkCreateInstance: " + vkResultName(r) + ")";
  }
  if (debug_utils) {
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (create_messenger) VK_CHECK(create_messenger(instance_, &dbg, nullptr, &messenger_));
  }
  return std::nullopt;
}

// Physical device: the given index, or the best-ranked usable one.
std::optional<std::string> VulkanContext::choosePhysicalDevice(const ContextOptions& o) {
  auto pds = physicalDevices(instance_);
  if (pds.empty()) return "no Vulkan device found";
  int chosen = -1;
  if (o.device >= 0) {
    if (o.device >= int(pds.size()))
      return "no Vulkan device " + std::to_string(o.device) + " (there are " + std::to_string(pds.size()) +
             "; see `tender devices`)";
    DeviceInfo d = describe(pds[size_t(o.device)], uint32_t(o.device));
    if (!d.usable) return "Vulkan device " + std::to_string(o.device) + " (" + d.name + ") lacks Vulkan 1.3 compute";
    chosen = o.device;
  } else {
    int best_rank = 1 << 30;
    for (uint32_t i = 0; i < pds.size(); ++i) {
      DeviceInfo d = describe(pds[i], i);
      if (!d.usable || (o.graphics && !findQueueFamily(pds[i], true))) continue;
      if (int(d.preference) < best_rank) {
        best_rank = int(d.preference);
        chosen = int(i);
      }
    }
    if (chosen < 0) return "no Vulkan 1.3 device with a compute queue found";
  }
  physical_ = pds[size_t(chosen)];
  info_ = describe(physical_, uint32_t(chosen));
  vkGetPhysicalDeviceProperties(physical_, &props_);
  vkGetPhysicalDeviceMemoryProperties(physical_, &mem_props_);
  auto family = findQueueFamily(physical_, o.graphics);
  if (!family)
    return "Vulkan device " + info_.name + " has no " + (o.graphics ? "graphics+compute" : "compute") + " queue";
  queue_family_ = *family;
  {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, nullptr);
    std::vector<VkQueueFamilyProperties> fams(n);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, fams.data());
    timestamp_bits_ = fams[*family].timestampValidBits;
  }
  timestamp_period_ = props_.limits.timestampPeriod;
  return std::nullopt;
}

// Device: Vulkan 1.3 synchronization2, plus the requested extensions.
std::optional<std::string> VulkanContext::createDevice(const ContextOptions& o) {
  std::vector<const char*> dev_exts;
  for (auto& e : o.device_extensions) {
    if (!hasDeviceExtension(physical_, e)) return "Vulkan device extension " + e + " is not available on " + info_.name;
    dev_exts.push_back(e.c_str());
  }
  VkPhysicalDeviceVulkan13Features f13{};
  f13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
  VkPhysicalDeviceVulkan12Features f12{};
  f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  f12.pNext = &f13;
  VkPhysicalDeviceFeatures2 f2{};
  f2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  f2.pNext = &f12;
  vkGetPhysicalDeviceFeatures2(physical_, &f2);
  if (!f13.synchronization2) return "Vulkan device " + info_.name + " lacks synchronization2";
  VkPhysicalDeviceVulkan13Features en13{};
  en13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
  en13.synchronization2 = VK_TRUE;
  en13.maintenance4 = f13.maintenance4;
  VkPhysicalDeviceVulkan12Features en12{};
  en12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  en12.pNext = &en13;
  en12.hostQueryReset = f12.hostQueryReset;
  en12.timelineSemaphore = f12.timelineSemaphore;
  en12.scalarBlockLayout = f12.scalarBlockLayout;
  // A fleet's batched tick reaches its sheets' slices by device address (64-bit arithmetic)
  en12.bufferDeviceAddress = f12.bufferDeviceAddress;
  VkPhysicalDeviceFeatures2 en2{};
  en2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  en2.pNext = &en12;
  en2.features.samplerAnisotropy = f2.features.samplerAnisotropy;
  en2.features.fillModeNonSolid = f2.features.fillModeNonSolid;
  en2.features.depthClamp = f2.features.depthClamp;
  en2.features.shaderInt64 = f2.features.shaderInt64;
  device_addresses_ = f12.bufferDeviceAddress && f2.features.shaderInt64;

  float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{};
  dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  dci.pNext = &en2;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = uint32_t(dev_exts.size());
  dci.ppEnabledExtensionNames = dev_exts.data();
  VkResult r = vkCreateDevice(physical_, &dci, nullptr, &device_);
  if (r != VK_SUCCESS) {
    device_ = VK_NULL_HANDLE;
    return "cannot create the Vulkan device on " + info_.name + " (" + vkResultName(r) + ")";
  }
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  return std::nullopt;
}

FloatRules VulkanContext::floatRules(const std::function<FloatRules()>& decide) {
  std::call_once(float_rules_once_, [&] { float_rules_ = decide(); });
  return float_rules_;
}

VkPipeline VulkanContext::sharedPipeline(const std::string& name,
                                         const std::function<VkPipeline(VkShaderModule&)>& make) {
  {
    std::lock_guard lock(pipelines_mutex_);
    if (auto it = pipelines_.find(name); it != pipelines_.end()) return it->second.first;
  }
  // Made outside the lock (seconds on a CPU device); a twin made meanwhile wins
  VkShaderModule module = VK_NULL_HANDLE;
  VkPipeline pipeline = make(module);
  std::lock_guard lock(pipelines_mutex_);
  auto [it, added] = pipelines_.try_emplace(name, pipeline, module);
  if (!added) {
    vkDestroyPipeline(device_, pipeline, nullptr);
    vkDestroyShaderModule(device_, module, nullptr);
  }
  return it->second.first;
}

VulkanContext::~VulkanContext() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    for (auto& [name, made] : pipelines_) {
      vkDestroyPipeline(device_, made.first, nullptr);
      vkDestroyShaderModule(device_, made.second, nullptr);
    }
    if (once_fence_) vkDestroyFence(device_, once_fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

} // namespace tender::gpu
