#include "level/level_save.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "engine/scene/gltf_writer.h"
#include "engine/scene/scene_assets.h"
#include "engine/transform/transform.h"

namespace game {

namespace fs = std::filesystem;
using engine::ecs::Entity;

namespace {

// The source file's image URIs and environment, which the loaded assets do not keep.
void copy_source_references(const fs::path& source, engine::scene::GltfSceneDesc& desc) {
  std::ifstream in(source);
  if (!in) throw std::runtime_error(source.string() + ": cannot reopen the level to copy its image and sky references");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
    if (j.contains("images"))
      for (const auto& img : j["images"]) desc.images.push_back(img.at("uri").get<std::string>());
    if (j.contains("scenes") && !j["scenes"].empty() && j["scenes"][0].contains("extras") &&
        j["scenes"][0]["extras"].contains("environment")) {
      const auto& e = j["scenes"][0]["extras"]["environment"];
      engine::scene::GltfEnvironmentDesc env;
      env.uri = e.at("uri").get<std::string>();
      env.strength = e.value("strength", 1.0f);
      if (e.contains("matrix")) {
        const auto m = e["matrix"].get<std::vector<float>>();
        if (m.size() != 16) throw std::runtime_error("scenes[0].extras.environment.matrix: expected 16 numbers");
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 4; ++r) env.matrix[c][r] = m[static_cast<std::size_t>(c * 4 + r)];
      }
      desc.environment = env;
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(source.string() + ": " + e.what());
  }
}

}  // namespace

fs::path save_level_gltf(engine::ecs::World& world, const fs::path& out) {
  const auto* origin = world.try_resource<LevelOrigin>();
  if (!origin) throw std::runtime_error("save: this world was not loaded from a level file");
  const auto& assets = world.resource<engine::scene::SceneAssets>();
  engine::scene::GltfSceneDesc desc;
  for (std::size_t i = 0; i < origin->meshes; ++i) desc.meshes.push_back(*assets.meshes[i]);
  desc.materials.assign(assets.materials.begin(), assets.materials.begin() + static_cast<std::ptrdiff_t>(origin->materials));
  copy_source_references(origin->source, desc);
  std::map<Entity, int> node_of;
  for (Entity e : origin->entities) {
    if (!world.alive(e)) continue;  // despawned in play: not saved
    node_of[e] = static_cast<int>(desc.nodes.size());
    engine::scene::GltfNodeDesc n;
    if (const auto* name = world.try_get<engine::scene::Name>(e)) n.name = name->value;
    if (const auto* t = world.try_get<engine::transform::Transform>(e)) n.transform = *t;
    if (const auto* m = world.try_get<engine::scene::MeshInstance>(e); m && m->mesh < origin->meshes) n.mesh = static_cast<int>(m->mesh);
    if (const auto* c = world.try_get<engine::scene::Camera>(e)) n.camera = *c;
    if (const auto* l = world.try_get<engine::scene::PunctualLight>(e)) n.light = *l;
    desc.nodes.push_back(n);
  }
  for (const auto& [e, index] : node_of) {
    const auto* p = world.try_get<engine::transform::Parent>(e);
    auto parent = p ? node_of.find(p->entity) : node_of.end();
    if (parent != node_of.end()) desc.nodes[static_cast<std::size_t>(parent->second)].children.push_back(index);
    else desc.roots.push_back(index);
  }
  std::sort(desc.roots.begin(), desc.roots.end());
  const fs::path path = out.empty() ? origin->source : out;
  engine::scene::write_gltf(path, desc);
  return path;
}

}  // namespace game
