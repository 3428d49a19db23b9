// find_open_space with its segments traced by the GPU backend against
// Embree's, on the thick-walled room (0.3 m walls, a ceiling and two walls
// wound inwards, furniture): a 7^3 grid whose outer layer stands inside the
// walls, which the links leave unlit and relocation moves into the room.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/gpu/gpu_ray_tracer.h"
#include "engine/rt/rt_scene.h"
#include "eval/method_runs.h"
#include "gpu_fixture.h"
#include "probes/open_space.h"

using namespace transgi;

// The same probes linked, the same relocated, their offsets to 1e-4 of a
// cell (the two tracers' hit distances differ by rounding).
TEST(GpuOpenSpace, TheGpuTracersSegmentsLinkAndRelocateTheProbesAsEmbreesDo) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  eval::LoadedScene loaded = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/thick_room/scene.gltf", "", 2);
  const engine::rt::RtScene& scene = loaded.app->world().resource<engine::rt::RtScene>();
  // Inset by half a wall: the outer layer stands inside the walls, floor and ceiling.
  const probes::ProbeGrid grid{scene.bounds_min() + 0.15f, scene.bounds_max() - 0.15f, glm::ivec3(7)};
  // The probes nearest the middle saw light: the room links to them.
  std::vector<std::uint8_t> saw(static_cast<std::size_t>(grid.count()), 0);
  saw[static_cast<std::size_t>(grid.index({3, 3, 3}))] = 1;
  saw[static_cast<std::size_t>(grid.index({3, 2, 3}))] = 1;

  engine::gpu::GpuRayTracer tracer(*ctx);
  const probes::OpenSpace cpu = probes::find_open_space(scene, grid, saw);
  const probes::OpenSpace gpu = probes::find_open_space(scene, grid, saw, {}, &tracer);
  std::printf("open space: %d probes, %d linked, %d relocated (Embree); %d linked, %d relocated (GPU)\n", grid.count(),
              cpu.open_count, cpu.relocated, gpu.open_count, gpu.relocated);
  ASSERT_GT(cpu.relocated, 0) << "some layer should stand in a wall";
  ASSERT_LT(cpu.open_count, grid.count()) << "some probes should stay unlinked (inside furniture or beyond the walls)";
  EXPECT_EQ(gpu.open_count, cpu.open_count);
  EXPECT_EQ(gpu.relocated, cpu.relocated);
  for (int q = 0; q < grid.count(); ++q) {
    const auto i = static_cast<std::size_t>(q);
    EXPECT_EQ(gpu.open[i], cpu.open[i]) << "probe " << q;
    EXPECT_LT(glm::length(gpu.offsets[i] - cpu.offsets[i]), 1e-4f * grid.min_spacing())
        << "probe " << q << ": offset (" << gpu.offsets[i].x << "," << gpu.offsets[i].y << "," << gpu.offsets[i].z
        << ") against Embree's (" << cpu.offsets[i].x << "," << cpu.offsets[i].y << "," << cpu.offsets[i].z << ")";
  }
}
