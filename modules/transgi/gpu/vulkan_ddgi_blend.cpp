#include "gpu/vulkan_ddgi_blend.h"

#include <stdexcept>
#include <string>

#include "gpu/shader_path.h"
#include "transgi_shared.h"

namespace transgi::gpu {

VulkanDdgiBlend::VulkanDdgiBlend(engine::gpu::VulkanContext& ctx) : ctx_(ctx) {
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("ddgi_blend.comp"), 4,
                                                              static_cast<std::uint32_t>(sizeof(DdgiBlendPush)));
}

double VulkanDdgiBlend::blend(std::vector<ddgi::OctahedralMap<glm::vec3>>& irradiance,
                              std::vector<ddgi::OctahedralMap<glm::vec2>>& distance,
                              const std::vector<std::vector<ddgi::RayRecord>>& records, const ddgi::DdgiSettings& s,
                              float hysteresis, bool clamp_brightness, float max_distance) {
  const std::size_t probes = irradiance.size();
  const auto m = static_cast<std::size_t>(s.rays_per_probe);
  if (distance.size() != probes || records.size() != probes || probes == 0)
    throw std::invalid_argument("VulkanDdgiBlend: " + std::to_string(probes) + " irradiance maps, " +
                                std::to_string(distance.size()) + " distance maps, " + std::to_string(records.size()) +
                                " record lists");
  const int in = irradiance[0].interior, dn = distance[0].interior;
  const auto isz = static_cast<std::size_t>((in + 2) * (in + 2)), dsz = static_cast<std::size_t>((dn + 2) * (dn + 2));
  std::vector<DdgiRayGpu> rays(probes * m);
  std::vector<std::uint32_t> flags(probes, 0);
  std::vector<float> irr(probes * isz * 3), dist(probes * dsz * 2);
  for (std::size_t q = 0; q < probes; ++q) {
    if (irradiance[q].interior != in || distance[q].interior != dn)
      throw std::invalid_argument("VulkanDdgiBlend: probe " + std::to_string(q) + "'s maps differ in size from probe 0's");
    if (!records[q].empty()) {
      if (records[q].size() != m)
        throw std::invalid_argument("VulkanDdgiBlend: probe " + std::to_string(q) + " has " + std::to_string(records[q].size()) +
                                    " rays, the settings say " + std::to_string(m));
      flags[q] = 1;
      for (std::size_t i = 0; i < m; ++i) {
        const auto& r = records[q][i];
        rays[q * m + i] = {r.direction.x, r.direction.y, r.direction.z, r.distance, r.radiance.x, r.radiance.y, r.radiance.z, 0};
      }
    }
    for (std::size_t t = 0; t < isz; ++t)
      for (int c = 0; c < 3; ++c) irr[(q * isz + t) * 3 + static_cast<std::size_t>(c)] = irradiance[q].texels[t][c];
    for (std::size_t t = 0; t < dsz; ++t)
      for (int c = 0; c < 2; ++c) dist[(q * dsz + t) * 2 + static_cast<std::size_t>(c)] = distance[q].texels[t][c];
  }
  engine::gpu::bind_at_least(ctx_, *pipeline_, 0, rays_, rays.size() * sizeof(DdgiRayGpu)).upload(std::span<const DdgiRayGpu>(rays));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 1, irradiance_, irr.size() * sizeof(float)).upload(std::span<const float>(irr));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 2, distance_, dist.size() * sizeof(float)).upload(std::span<const float>(dist));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 3, flags_, flags.size() * sizeof(std::uint32_t)).upload(std::span<const std::uint32_t>(flags));
  DdgiBlendPush push{};
  push.probes = static_cast<uint>(probes);
  push.rays_per_probe = static_cast<uint>(m);
  push.irradiance_interior = static_cast<uint>(in);
  push.distance_interior = static_cast<uint>(dn);
  push.hysteresis = hysteresis;
  push.irradiance_threshold = s.irradiance_threshold;
  push.brightness_threshold = s.brightness_threshold;
  push.irradiance_gamma = s.irradiance_gamma;
  push.distance_exponent = s.distance_exponent;
  push.max_distance = max_distance;
  push.clamp_brightness = clamp_brightness ? 1u : 0u;
  push.max_backfaces = static_cast<int>(static_cast<float>(s.rays_per_probe) * s.random_ray_backface_threshold);
  const double ms = ctx_.submit_and_wait(
      [&](VkCommandBuffer cmd) { pipeline_->record_dispatch(cmd, static_cast<std::uint32_t>(probes), 1, 1, &push); });
  irradiance_.download(std::span<float>(irr));
  distance_.download(std::span<float>(dist));
  for (std::size_t q = 0; q < probes; ++q) {
    for (std::size_t t = 0; t < isz; ++t) irradiance[q].texels[t] = glm::vec3(irr[(q * isz + t) * 3], irr[(q * isz + t) * 3 + 1], irr[(q * isz + t) * 3 + 2]);
    for (std::size_t t = 0; t < dsz; ++t) distance[q].texels[t] = glm::vec2(dist[(q * dsz + t) * 2], dist[(q * dsz + t) * 2 + 1]);
  }
  return ms;
}

}  // namespace transgi::gpu
