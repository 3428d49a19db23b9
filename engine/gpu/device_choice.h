#pragma once
// Which Vulkan device the engine runs its compute on: a discrete GPU first,
// then an integrated one, a virtual one, and the CPU driver (Mesa's lavapipe)
// last. A requested name (--device, or ENGINE_GPU_DEVICE) overrides the rank.
// Kept apart from the Vulkan calls so the rule is tested without a driver.
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace engine::gpu {

enum class DeviceKind { Discrete, Integrated, Virtual, Cpu, Other };

struct DeviceCandidate {
  std::string name;
  DeviceKind kind = DeviceKind::Other;
  bool has_compute_queue = true;
};

struct DeviceChoice {
  std::optional<std::size_t> index;  // empty: none fits, see why
  std::string why;
};

// requested: empty for the ranked default; otherwise a case-insensitive
// substring of the device's name ("llvmpipe", "rtx"). An unmatched request
// is an error listing the names there are, not a silent fallback.
DeviceChoice choose_device(std::span<const DeviceCandidate> devices, std::string_view requested);

const char* device_kind_name(DeviceKind kind);

}  // namespace engine::gpu
