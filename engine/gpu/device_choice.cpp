#include "engine/gpu/device_choice.h"

#include <algorithm>
#include <cctype>

namespace engine::gpu {
namespace {

int rank(DeviceKind k) {
  switch (k) {
    case DeviceKind::Discrete: return 0;
    case DeviceKind::Integrated: return 1;
    case DeviceKind::Virtual: return 2;
    case DeviceKind::Cpu: return 3;
    case DeviceKind::Other: return 4;
  }
  return 5;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

const char* device_kind_name(DeviceKind kind) {
  switch (kind) {
    case DeviceKind::Discrete: return "discrete GPU";
    case DeviceKind::Integrated: return "integrated GPU";
    case DeviceKind::Virtual: return "virtual GPU";
    case DeviceKind::Cpu: return "CPU";
    case DeviceKind::Other: return "other";
  }
  return "?";
}

DeviceChoice choose_device(std::span<const DeviceCandidate> devices, std::string_view requested) {
  std::string names;
  for (const auto& d : devices) names += (names.empty() ? "" : ", ") + ("'" + d.name + "'");
  if (devices.empty()) return {std::nullopt, "no Vulkan device found"};

  const std::string want = lower(requested);
  std::optional<std::size_t> best;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    const auto& d = devices[i];
    if (!d.has_compute_queue) continue;
    if (!want.empty() && lower(d.name).find(want) == std::string::npos) continue;
    if (!best || rank(d.kind) < rank(devices[*best].kind)) best = i;  // first of equal rank wins: stable
  }
  if (best) return {best, ""};
  if (!want.empty()) return {std::nullopt, "no Vulkan device named like '" + std::string(requested) + "' (there are " + names + ")"};
  return {std::nullopt, "no Vulkan device with a compute queue (there are " + names + ")"};
}

}  // namespace engine::gpu
