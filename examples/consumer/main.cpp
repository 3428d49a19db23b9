// The smallest game on an installed TransGI: load a level, add the TransGI
// plugin with the real-time preset, let its probes light the level, write
// the frame; then move an object, run a few frames, write that too.
//
//   consumer LEVEL.gltf MODEL.tgm STILL.exr MOVED.exr [OBJECT]
//
// STILL.exr is the frame `transgi render --preset realtime --pass full
// --frames 32` makes (the same settings, the same frames).
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include "engine/app/app.h"
#include "engine/image/exr.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/gltf_loader.h"
#include "engine/transform/transform.h"
#include "model/model_file.h"
#include "runtime/gi_frame.h"
#include "runtime/probe_placement.h"
#include "runtime/transgi_plugin.h"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: consumer LEVEL.gltf MODEL.tgm STILL.exr MOVED.exr [OBJECT]\n");
    return 2;
  }
  try {
    using namespace engine;
    app::App app(app::AppOptions{.jobs = {.threads = 2}});
    app.add_plugin<rt::RtPlugin>();
    const scene::GltfLoadResult level = scene::load_gltf(app.world(), argv[1]);
    app.update();
    ecs::Entity camera, object;
    const std::string object_name = argc > 5 ? argv[5] : "TableTop";
    for (ecs::Entity e : level.entities) {
      if (camera.is_null() && app.world().has<scene::Camera>(e)) camera = e;
      if (const auto* name = app.world().try_get<scene::Name>(e); name && name->value == object_name) object = e;
    }
    if (camera.is_null()) throw std::runtime_error(std::string(argv[1]) + ": no camera");
    if (object.is_null()) throw std::runtime_error(std::string(argv[1]) + ": no object named '" + object_name + "'");

    transgi::runtime::TransGISettings settings = transgi::runtime::realtime_preset();
    settings.probes.seed = 1;  // as `transgi render` seeds them
    app.add_plugin<transgi::runtime::TransGIPlugin>(settings);
    transgi::runtime::attach_latent_meshes(
        app.world(), std::make_shared<const transgi::model::TransferModel>(transgi::model::load_model(argv[2])));
    transgi::runtime::spawn_probes(app.world(), transgi::runtime::ProbePlacement{});
    auto& frame = app.world().resource<transgi::runtime::GiFrame>();
    frame.camera = camera;
    frame.width = 160;
    frame.height = 90;
    frame.antialias_passes = true;
    for (int f = 0; f < 32; ++f) app.jobs().run([&] { app.update(); });
    image::write_exr(argv[3], frame.full);
    app.world().get_mut<transform::Transform>(object).translation += glm::vec3(0.3f, 0.0f, 0.0f);
    for (int f = 0; f < 8; ++f) app.jobs().run([&] { app.update(); });
    image::write_exr(argv[4], frame.full);
    std::printf("wrote %s and %s (160x90, TransGI %s)\n", argv[3], argv[4], frame.backend.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
}
