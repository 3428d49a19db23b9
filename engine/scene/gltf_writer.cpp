#include "engine/scene/gltf_writer.h"

#include <nlohmann/json.hpp>

#include <cstring>
#include <map>
#include <set>
#include <span>

#include "engine/io/atomic_file.h"

namespace engine::scene {

namespace {

using json = nlohmann::json;

struct BinaryBuilder {
  std::vector<std::byte> bytes;
  json views = json::array();
  json accessors = json::array();

  template <class T>
  int add(const std::vector<T>& data, const char* type, int component_type, int target, std::optional<std::pair<json, json>> min_max = {}) {
    while (bytes.size() % 4) bytes.push_back(std::byte{0});
    const std::size_t offset = bytes.size();
    const auto* p = reinterpret_cast<const std::byte*>(data.data());
    bytes.insert(bytes.end(), p, p + data.size() * sizeof(T));
    views.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size() * sizeof(T)}, {"target", target}});
    json acc = {{"bufferView", views.size() - 1}, {"componentType", component_type}, {"type", type}};
    std::size_t count = data.size();
    if (std::strcmp(type, "VEC3") == 0) count = data.size() * sizeof(T) / 12;
    else if (std::strcmp(type, "VEC2") == 0) count = data.size() * sizeof(T) / 8;
    acc["count"] = count;
    if (min_max) {
      acc["min"] = min_max->first;
      acc["max"] = min_max->second;
    }
    accessors.push_back(acc);
    return static_cast<int>(accessors.size() - 1);
  }
};

json vec(const glm::vec3& v) { return json::array({v.x, v.y, v.z}); }

json material_json(const material::Material& m, std::set<std::string>& used) {
  json j = {{"name", m.name},
            {"pbrMetallicRoughness",
             {{"baseColorFactor", {m.base_color_factor.r, m.base_color_factor.g, m.base_color_factor.b, m.base_color_factor.a}},
              {"metallicFactor", m.metallic_factor},
              {"roughnessFactor", m.roughness_factor}}},
            {"doubleSided", m.double_sided}};
  if (m.base_color_texture >= 0) j["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", m.base_color_texture}};
  if (m.is_emissive()) {
    j["emissiveFactor"] = vec(m.emissive_factor);
    if (m.emissive_strength != 1.0f) {
      j["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", m.emissive_strength}};
      used.insert("KHR_materials_emissive_strength");
    }
  }
  if (m.specular_factor != 1.0f || m.specular_color_factor != glm::vec3(1.0f)) {
    j["extensions"]["KHR_materials_specular"] = {{"specularFactor", m.specular_factor},
                                                 {"specularColorFactor", vec(m.specular_color_factor)}};
    used.insert("KHR_materials_specular");
  }
  if (m.alpha_mode == material::AlphaMode::Mask) {
    j["alphaMode"] = "MASK";
    j["alphaCutoff"] = m.alpha_cutoff;
  }
  return j;
}

}  // namespace

void write_gltf(const std::filesystem::path& path, const GltfSceneDesc& scene) {
  BinaryBuilder bin;
  std::set<std::string> used;
  json meshes = json::array();
  for (const MeshAsset& m : scene.meshes) {
    const int pos = bin.add(m.positions, "VEC3", 5126, 34962, std::make_pair(vec(m.bounds_min), vec(m.bounds_max)));
    const int nrm = bin.add(m.normals, "VEC3", 5126, 34962);
    const int uv = m.uvs.empty() ? -1 : bin.add(m.uvs, "VEC2", 5126, 34962);
    // One primitive per material, in material order, sharing the vertex accessors.
    std::map<std::uint32_t, std::vector<std::uint32_t>> by_material;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      auto& idx = by_material[m.triangle_material[t]];
      idx.insert(idx.end(), {m.triangles[t].x, m.triangles[t].y, m.triangles[t].z});
    }
    json prims = json::array();
    for (const auto& [mat, idx] : by_material) {
      json attrs = {{"POSITION", pos}, {"NORMAL", nrm}};
      if (uv >= 0) attrs["TEXCOORD_0"] = uv;
      prims.push_back({{"attributes", attrs}, {"indices", bin.add(idx, "SCALAR", 5125, 34963)}, {"material", mat}, {"mode", 4}});
    }
    meshes.push_back({{"name", m.name}, {"primitives", prims}});
  }

  json materials = json::array();
  for (const auto& m : scene.materials) materials.push_back(material_json(m, used));

  json nodes = json::array(), cameras = json::array(), lights = json::array();
  for (const GltfNodeDesc& n : scene.nodes) {
    json j = {{"name", n.name}};
    const auto& t = n.transform;
    if (t.translation != glm::vec3(0.0f)) j["translation"] = vec(t.translation);
    if (t.rotation != glm::quat(1, 0, 0, 0)) j["rotation"] = {t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w};
    if (t.scale != 1.0f) j["scale"] = {t.scale, t.scale, t.scale};
    if (n.mesh >= 0) j["mesh"] = n.mesh;
    if (!n.children.empty()) j["children"] = n.children;
    if (n.camera) {
      json persp = {{"yfov", n.camera->yfov_radians}, {"znear", n.camera->znear}};
      if (n.camera->aspect_ratio > 0) persp["aspectRatio"] = n.camera->aspect_ratio;
      cameras.push_back({{"type", "perspective"}, {"perspective", persp}});
      j["camera"] = cameras.size() - 1;
    }
    if (n.light) {
      const auto& l = *n.light;
      json lj = {{"type", l.type == PunctualLight::Type::Point ? "point" : l.type == PunctualLight::Type::Spot ? "spot" : "directional"},
                 {"color", vec(l.color)},
                 {"intensity", l.intensity}};
      if (l.type == PunctualLight::Type::Spot)
        lj["spot"] = {{"innerConeAngle", l.inner_cone_angle}, {"outerConeAngle", l.outer_cone_angle}};
      if (l.type == PunctualLight::Type::Directional && l.angular_radius > 0) lj["extras"] = {{"angular_radius", l.angular_radius}};
      lights.push_back(lj);
      j["extensions"]["KHR_lights_punctual"] = {{"light", lights.size() - 1}};
      used.insert("KHR_lights_punctual");
    }
    nodes.push_back(j);
  }

  const std::string bin_name = path.stem().string() + ".bin";
  json root = {{"asset", {{"version", "2.0"}, {"generator", "TransGI content generator"}}},
               {"scene", 0},
               {"scenes", {{{"nodes", scene.roots}}}},
               {"nodes", nodes},
               {"meshes", meshes},
               {"materials", materials},
               {"accessors", bin.accessors},
               {"bufferViews", bin.views},
               {"buffers", {{{"uri", bin_name}, {"byteLength", bin.bytes.size()}}}}};
  if (!cameras.empty()) root["cameras"] = cameras;
  if (!scene.images.empty()) {
    json images = json::array(), textures = json::array();
    for (std::size_t i = 0; i < scene.images.size(); ++i) {
      images.push_back({{"uri", scene.images[i]}});
      textures.push_back({{"source", i}, {"sampler", 0}});
    }
    root["images"] = images;
    root["textures"] = textures;
    root["samplers"] = json::array({json::object({{"wrapS", 10497}, {"wrapT", 10497}})});
  }
  if (!lights.empty()) root["extensions"]["KHR_lights_punctual"] = {{"lights", lights}};
  if (!used.empty()) root["extensionsUsed"] = used;
  if (scene.environment) {
    json m = json::array();
    for (int k = 0; k < 16; ++k) m.push_back((&scene.environment->matrix[0][0])[k]);
    root["scenes"][0]["extras"]["environment"] = {{"uri", scene.environment->uri}, {"strength", scene.environment->strength}, {"matrix", m}};
  }
  const std::string text = root.dump(1) + "\n";
  io::write_file_atomically(path.parent_path() / bin_name, bin.bytes);
  io::write_file_atomically(path, std::as_bytes(std::span(text.data(), text.size())));
}

}  // namespace engine::scene
