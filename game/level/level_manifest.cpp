#include "level/level_manifest.h"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "engine/scene/find_named.h"
#include "engine/scene/procedural.h"
#include "engine/scene/scene_assets.h"
#include "engine/transform/transform.h"

namespace game {

namespace {

using nlohmann::json;
using engine::ecs::Entity;
using engine::ecs::World;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& field, const std::string& why) {
  throw std::runtime_error(file.string() + ": " + field + ": " + why);
}

float number(const json& j, const std::filesystem::path& file, const std::string& field) {
  if (!j.is_number()) fail(file, field, "expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v) || std::abs(v) > 1e6) fail(file, field, "must be a finite number below 1e6");
  return static_cast<float>(v);
}

glm::vec3 vec3(const json& j, const std::filesystem::path& file, const std::string& field) {
  if (!j.is_array() || j.size() != 3) fail(file, field, "expected [x, y, z]");
  return {number(j[0], file, field + "[0]"), number(j[1], file, field + "[1]"), number(j[2], file, field + "[2]")};
}

std::string text(const json& j, const std::filesystem::path& file, const std::string& field) {
  if (!j.is_string()) fail(file, field, "expected a string");
  return j.get<std::string>();
}

engine::script::Script script_of(const json& j, const std::filesystem::path& file, const std::string& field) {
  engine::script::Script s;
  if (j.is_string()) {
    s.path = j.get<std::string>();
    return s;
  }
  if (!j.is_object() || !j.contains("file")) fail(file, field, "expected \"file.lua\" or {\"file\": ..., \"properties\": {...}}");
  s.path = text(j["file"], file, field + ".file");
  if (j.contains("properties")) {
    if (!j["properties"].is_object()) fail(file, field + ".properties", "expected an object");
    for (const auto& [k, v] : j["properties"].items()) {
      const std::string f = field + ".properties." + k;
      if (v.is_boolean()) s.overrides[k] = v.get<bool>();
      else if (v.is_number()) s.overrides[k] = static_cast<double>(number(v, file, f));
      else if (v.is_string()) s.overrides[k] = v.get<std::string>();
      else fail(file, f, "expected a number, boolean or string");
    }
  }
  return s;
}

engine::scene::PunctualLight light_of(const json& j, const std::filesystem::path& file, const std::string& field) {
  engine::scene::PunctualLight l;
  const std::string type = j.contains("type") ? text(j["type"], file, field + ".type") : "point";
  if (type == "point") l.type = engine::scene::PunctualLight::Type::Point;
  else if (type == "spot") l.type = engine::scene::PunctualLight::Type::Spot;
  else if (type == "directional") l.type = engine::scene::PunctualLight::Type::Directional;
  else fail(file, field + ".type", "expected point, spot or directional, got '" + type + "'");
  if (j.contains("color")) l.color = vec3(j["color"], file, field + ".color");
  if (j.contains("intensity")) l.intensity = number(j["intensity"], file, field + ".intensity");
  if (j.contains("range")) l.range = number(j["range"], file, field + ".range");
  if (j.contains("enabled")) l.enabled = j["enabled"].is_boolean() ? j["enabled"].get<bool>() : (fail(file, field + ".enabled", "expected a boolean"), true);
  if (l.intensity < 0 || l.range < 0 || glm::any(glm::lessThan(l.color, glm::vec3(0.0f))))
    fail(file, field, "color, intensity and range must be >= 0");
  return l;
}

}  // namespace

LevelManifest load_manifest(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot open the level's game file");
  json root;
  try {
    root = json::parse(in);
  } catch (const json::exception& e) {  // syntax, and numbers out of double's range
    throw std::runtime_error(file.string() + ": not valid JSON: " + e.what());
  }
  if (!root.is_object()) fail(file, "(root)", "expected an object");
  LevelManifest m;
  m.file = file;
  m.scripts_dir = file.parent_path() / (root.contains("scripts_dir") ? text(root["scripts_dir"], file, "scripts_dir") : "scripts");
  if (root.contains("meshes")) {
    if (!root["meshes"].is_array()) fail(file, "meshes", "expected an array");
    for (std::size_t i = 0; i < root["meshes"].size(); ++i) {
      const json& j = root["meshes"][i];
      const std::string f = "meshes[" + std::to_string(i) + "]";
      ManifestMesh mesh;
      mesh.name = text(j.value("name", json()), file, f + ".name");
      mesh.shape = text(j.value("shape", json("box")), file, f + ".shape");
      if (mesh.shape != "box" && mesh.shape != "sphere") fail(file, f + ".shape", "expected box or sphere");
      mesh.size = vec3(j.value("size", json()), file, f + ".size");
      if (glm::any(glm::lessThanEqual(mesh.size, glm::vec3(0.0f)))) fail(file, f + ".size", "must be positive");
      if (j.contains("albedo")) mesh.albedo = vec3(j["albedo"], file, f + ".albedo");
      if (j.contains("roughness")) mesh.roughness = number(j["roughness"], file, f + ".roughness");
      if (j.contains("metallic")) mesh.metallic = number(j["metallic"], file, f + ".metallic");
      if (glm::any(glm::lessThan(mesh.albedo, glm::vec3(0.0f))) || glm::any(glm::greaterThan(mesh.albedo, glm::vec3(1.0f))))
        fail(file, f + ".albedo", "components must be in [0, 1]");
      m.meshes.push_back(mesh);
    }
  }
  if (root.contains("entities")) {
    if (!root["entities"].is_array()) fail(file, "entities", "expected an array");
    for (std::size_t i = 0; i < root["entities"].size(); ++i) {
      const json& j = root["entities"][i];
      const std::string f = "entities[" + std::to_string(i) + "]";
      ManifestEntity e;
      e.name = text(j.value("name", json()), file, f + ".name");
      if (j.contains("mesh")) e.mesh = text(j["mesh"], file, f + ".mesh");
      if (j.contains("parent")) e.parent = text(j["parent"], file, f + ".parent");
      if (j.contains("position")) e.position = vec3(j["position"], file, f + ".position");
      if (j.contains("rotation_degrees")) e.euler_degrees = vec3(j["rotation_degrees"], file, f + ".rotation_degrees");
      if (j.contains("light")) e.light = light_of(j["light"], file, f + ".light");
      if (j.contains("script")) e.script = script_of(j["script"], file, f + ".script");
      m.entities.push_back(e);
    }
  }
  if (root.contains("attach")) {
    if (!root["attach"].is_object()) fail(file, "attach", "expected {\"node name\": script}");
    for (const auto& [node, s] : root["attach"].items()) m.attach[node] = script_of(s, file, "attach." + node);
  }
  return m;
}


void apply_manifest(World& world, const LevelManifest& manifest) {
  auto& assets = world.resource<engine::scene::SceneAssets>();
  for (const ManifestMesh& mm : manifest.meshes) {
    engine::material::Material mat;
    mat.name = mm.name;
    mat.base_color_factor = glm::vec4(mm.albedo, 1.0f);
    mat.roughness_factor = mm.roughness;
    mat.metallic_factor = mm.metallic;
    const auto material = static_cast<std::uint32_t>(assets.materials.size());
    assets.materials.push_back(mat);
    auto mesh = std::make_shared<engine::scene::MeshAsset>(
        mm.shape == "box" ? engine::scene::make_box(mm.size, false, material)
                          : engine::scene::make_uv_sphere(mm.size.x, 32, 16, material));
    mesh->name = mm.name;
    assets.meshes.push_back(mesh);
  }
  for (const ManifestEntity& me : manifest.entities) {
    const Entity e = world.spawn();
    world.emplace<engine::scene::Name>(e, engine::scene::Name{me.name});
    engine::transform::Transform t = engine::transform::Transform::from_translation(me.position);
    t.rotation = glm::quat(glm::radians(me.euler_degrees));
    world.emplace<engine::transform::Transform>(e, t);
    if (!me.parent.empty()) {
      const Entity p = engine::scene::find_named(world, me.parent);
      if (p.is_null()) throw std::runtime_error(manifest.file.string() + ": entity '" + me.name + "': no parent named '" + me.parent + "'");
      world.emplace<engine::transform::Parent>(e, engine::transform::Parent{p});
    }
    if (!me.mesh.empty()) {
      std::uint32_t index = UINT32_MAX;
      for (std::size_t i = 0; i < assets.meshes.size(); ++i)
        if (assets.meshes[i]->name == me.mesh) index = static_cast<std::uint32_t>(i);
      if (index == UINT32_MAX) throw std::runtime_error(manifest.file.string() + ": entity '" + me.name + "': no mesh named '" + me.mesh + "'");
      world.emplace<engine::scene::MeshInstance>(e, engine::scene::MeshInstance{index});
    }
    if (me.light) world.emplace<engine::scene::PunctualLight>(e, *me.light);
    if (me.script) world.emplace<engine::script::Script>(e, *me.script);
  }
  for (const auto& [node, script] : manifest.attach) {
    const Entity e = engine::scene::find_named(world, node);
    if (e.is_null()) throw std::runtime_error(manifest.file.string() + ": attach: no node named '" + node + "' in the level");
    world.emplace<engine::script::Script>(e, script);
  }
}

}  // namespace game
