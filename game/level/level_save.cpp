#include "level/level_save.h"

#include <fstream>
#include <span>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "engine/io/atomic_file.h"
#include "engine/scene/components.h"
#include "engine/scene/gltf_loader.h"
#include "engine/transform/transform.h"

namespace game {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

bool is_relative_uri(const std::string& uri) { return !uri.empty() && uri.find(':') == std::string::npos && uri[0] != '/'; }

// A level loads files only from its own folder, so a copy saved elsewhere
// takes the files it names along (the same relative paths).
void copy_referenced(const json& holder, const char* key, const fs::path& from_dir, const fs::path& to_dir) {
  if (!holder.contains(key) || !holder[key].is_string()) return;
  const std::string uri = holder[key].get<std::string>();
  if (!is_relative_uri(uri)) return;
  const fs::path target = to_dir / uri;
  fs::create_directories(target.parent_path());
  fs::copy_file(from_dir / uri, target, fs::copy_options::overwrite_existing);
}

}  // namespace

fs::path save_level_gltf(engine::ecs::World& world, const fs::path& out) {
  const auto* origin = world.try_resource<LevelOrigin>();
  if (!origin) throw std::runtime_error("save: this world was not loaded from a level file");
  json root;
  {
    std::ifstream in(origin->source);
    if (!in) throw std::runtime_error(origin->source.string() + ": cannot reopen the level to save into it");
    try {
      root = json::parse(in);
    } catch (const json::exception& e) {
      throw std::runtime_error(origin->source.string() + ": " + e.what());
    }
  }
  json& nodes = root["nodes"];
  world.view<const engine::scene::GltfNodeSource>().each([&](engine::ecs::Entity e, const engine::scene::GltfNodeSource& src) {
    if (src.node >= nodes.size()) return;
    json& node = nodes[src.node];
    const std::string name = node.value("name", "nodes[" + std::to_string(src.node) + "]");
    if (const auto* t = world.try_get<engine::transform::Transform>(e); t && !(*t == src.loaded)) {
      if (src.baked_scale)
        throw std::runtime_error("save: node '" + name + "' has a non-uniform scale baked into its mesh; moving it cannot be saved");
      node.erase("matrix");
      node["translation"] = {t->translation.x, t->translation.y, t->translation.z};
      node["rotation"] = {t->rotation.x, t->rotation.y, t->rotation.z, t->rotation.w};
      node["scale"] = {t->scale, t->scale, t->scale};
    }
    const auto* l = world.try_get<engine::scene::PunctualLight>(e);
    if (l && node.contains("extensions") && node["extensions"].contains("KHR_lights_punctual")) {
      const auto index = node["extensions"]["KHR_lights_punctual"].value("light", -1);
      json& lights = root["extensions"]["KHR_lights_punctual"]["lights"];
      if (index >= 0 && static_cast<std::size_t>(index) < lights.size()) {
        json& light = lights[static_cast<std::size_t>(index)];
        light["color"] = {l->color.r, l->color.g, l->color.b};
        light["intensity"] = l->enabled ? l->intensity : 0.0f;  // glTF has no "off": an off light is saved dark
        if (l->range > 0) light["range"] = l->range;
        else light.erase("range");
      }
    }
  });
  const fs::path path = out.empty() ? origin->source : out;
  const fs::path from_dir = origin->source.parent_path(), to_dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (fs::absolute(from_dir).lexically_normal() != fs::absolute(to_dir).lexically_normal()) {
    if (root.contains("buffers")) for (const json& b : root["buffers"]) copy_referenced(b, "uri", from_dir, to_dir);
    if (root.contains("images")) for (const json& i : root["images"]) copy_referenced(i, "uri", from_dir, to_dir);
    if (root.contains("scenes"))
      for (const json& s : root["scenes"])
        if (s.contains("extras") && s["extras"].contains("environment")) copy_referenced(s["extras"]["environment"], "uri", from_dir, to_dir);
  }
  const std::string text = root.dump(1) + "\n";
  engine::io::write_file_atomically(path, std::as_bytes(std::span(text.data(), text.size())));
  return path;
}

}  // namespace game
