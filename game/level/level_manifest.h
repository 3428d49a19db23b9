#pragma once
// A level's game layer (game.json beside the level's glTF): the extra meshes
// the game adds (built from boxes and spheres, with their own materials), the
// extra entities (props, lights, script holders) and the scripts attached to
// the glTF's own nodes. The glTF stays what the GI model was baked for;
// what the game adds is lit by the probes through the diffuse fallback.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "engine/ecs/world.h"
#include "engine/scene/components.h"
#include "engine/script/script_component.h"

namespace game {

struct ManifestMesh {
  std::string name;
  std::string shape;           // "box" (size = half extents) or "sphere" (size.x = radius)
  glm::vec3 size{0.5f};
  glm::vec3 albedo{0.8f};
  float roughness = 0.6f, metallic = 0.0f;
};

struct ManifestEntity {
  std::string name;
  std::string mesh;    // a game mesh or a glTF mesh name; empty = none
  std::string parent;  // an entity name; empty = the world
  glm::vec3 position{0.0f};
  glm::vec3 euler_degrees{0.0f};
  std::optional<engine::scene::PunctualLight> light;
  std::optional<engine::script::Script> script;
};

struct LevelManifest {
  std::filesystem::path file;
  std::filesystem::path scripts_dir;  // where Script paths are resolved
  std::vector<ManifestMesh> meshes;
  std::vector<ManifestEntity> entities;
  // glTF node name -> its script.
  std::map<std::string, engine::script::Script> attach;
};

// Throws std::runtime_error naming the file and the field on bad input.
LevelManifest load_manifest(const std::filesystem::path& file);

// Adds the meshes to SceneAssets, spawns the entities and attaches the
// scripts. Throws naming the manifest and entity when a name is unknown.
void apply_manifest(engine::ecs::World& world, const LevelManifest& manifest);

}  // namespace game
