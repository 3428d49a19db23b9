#include "cli/reference_view.h"

#include "engine/render/camera_rays.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/transform/transform.h"

namespace transgi::cli {

engine::image::ImageRGB reference_gi_now(eval::LoadedScene& scene, int width, int height, int spp,
                                         const std::function<void(int, int)>& progress) {
  using namespace engine;
  ecs::World& world = scene.app->world();
  const auto& assets = world.resource<scene::SceneAssets>();
  const render::LightSet lights(world.resource<rt::RtScene>(), render::gather_punctual_lights(world),
                                assets.environment ? &*assets.environment : nullptr);
  const render::CameraRays rays(world.get<scene::Camera>(scene.camera), world.get<transform::WorldTransform>(scene.camera),
                                width, height);
  render::PathTracer pt(world.resource<rt::RtScene>(), lights, rays, width, height, render::PathTracerSettings{.seed = 1});
  scene.app->jobs().run([&] { pt.render(spp, progress); });
  return pt.image(render::Pass::Gi);
}

}  // namespace transgi::cli
