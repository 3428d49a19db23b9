// glTF importer: structure, materials, lights, cameras, environment, and a
// clear error (naming file and field) for each kind of bad input.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "engine/image/exr.h"
#include "engine/render/light_set.h"
#include "engine/scene/components.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_assets.h"
#include "engine/transform/transform.h"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace engine;
using namespace engine::scene;

namespace {

struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() / ("gltf_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

// A unit quad in the XY plane: 4 positions, 4 normals, 4 UVs, 6 u16 indices.
std::vector<unsigned char> quad_bin(float nan_at = -1) {
  std::vector<float> pos = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  if (nan_at >= 0) pos[static_cast<std::size_t>(nan_at)] = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> nrm = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const std::vector<float> uv = {0, 0, 1, 0, 1, 1, 0, 1};
  const std::vector<std::uint16_t> idx = {0, 1, 2, 0, 2, 3};
  std::vector<unsigned char> b(48 + 48 + 32 + 12);
  std::memcpy(b.data(), pos.data(), 48);
  std::memcpy(b.data() + 48, nrm.data(), 48);
  std::memcpy(b.data() + 96, uv.data(), 32);
  std::memcpy(b.data() + 128, idx.data(), 12);
  return b;
}

json quad_gltf() {
  return json::parse(R"({
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0, 2]}],
    "nodes": [
      {"name": "parent", "mesh": 0, "translation": [1, 2, 3], "children": [1]},
      {"name": "child", "mesh": 0, "scale": [2, 2, 2]},
      {"name": "cam", "camera": 0, "rotation": [0, 0.7071068, 0, 0.7071068]}
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.1}}],
    "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                                "indices": 3, "material": 0}]}],
    "materials": [{"name": "plastic", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1],
                    "metallicFactor": 0, "roughnessFactor": 0.3}, "doubleSided": true,
                   "extensions": {"KHR_materials_specular": {"specularFactor": 0, "specularColorFactor": [0, 0, 0]},
                                  "KHR_materials_emissive_strength": {"emissiveStrength": 5}},
                   "emissiveFactor": [1, 0.5, 0]}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
      {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
      {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}
    ],
    "bufferViews": [
      {"buffer": 0, "byteOffset": 0, "byteLength": 48},
      {"buffer": 0, "byteOffset": 48, "byteLength": 48},
      {"buffer": 0, "byteOffset": 96, "byteLength": 32},
      {"buffer": 0, "byteOffset": 128, "byteLength": 12}
    ],
    "buffers": [{"uri": "quad.bin", "byteLength": 140}]
  })");
}

fs::path write_scene(const TempDir& d, const json& j, const std::vector<unsigned char>& bin = quad_bin(),
                     const std::string& name = "scene.gltf") {
  std::ofstream(d.path / "quad.bin", std::ios::binary).write(reinterpret_cast<const char*>(bin.data()),
                                                            static_cast<std::streamsize>(bin.size()));
  std::ofstream(d.path / name) << j.dump(2);
  return d.path / name;
}

// Loads and expects a GltfError whose message contains every fragment.
void expect_rejected(const fs::path& file, std::initializer_list<std::string> fragments) {
  ecs::World w;
  try {
    load_gltf(w, file);
    ADD_FAILURE() << "expected GltfError for " << file;
  } catch (const GltfError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.filename().string()), std::string::npos) << "message must name the file: " << msg;
    for (const std::string& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << "missing '" << f << "' in: " << msg;
  }
}

}  // namespace

TEST(GltfLoader, NodesBecomeEntitiesSharingOneMeshAsset) {
  TempDir d;
  ecs::World w;
  const GltfLoadResult r = load_gltf(w, write_scene(d, quad_gltf()));
  ASSERT_EQ(r.entities.size(), 3u);
  const auto& assets = w.resource<SceneAssets>();
  ASSERT_EQ(assets.meshes.size(), 1u) << "two nodes using one glTF mesh share one mesh asset";
  EXPECT_EQ(assets.meshes[0]->triangle_count(), 2u);
  EXPECT_EQ(assets.meshes[0]->uvs.size(), 4u);
  const ecs::Entity parent = r.entities[0], child = r.entities[1], cam = r.entities[2];
  EXPECT_EQ(w.get<MeshInstance>(parent).mesh, 0u);
  EXPECT_EQ(w.get<MeshInstance>(child).mesh, 0u);
  EXPECT_EQ(w.get<transform::Parent>(child).entity, parent);
  EXPECT_FALSE(w.has<transform::Parent>(parent));
  EXPECT_EQ(w.get<transform::Transform>(parent).translation, glm::vec3(1, 2, 3));
  EXPECT_FLOAT_EQ(w.get<transform::Transform>(child).scale, 2.0f);
  EXPECT_EQ(w.get<Name>(child).value, "child");
  const Camera& c = w.get<Camera>(cam);
  EXPECT_FLOAT_EQ(c.yfov_radians, 0.8f);
  EXPECT_FLOAT_EQ(c.aspect_ratio, 1.5f);
}

TEST(GltfLoader, MaterialFactorsAndExtensions) {
  TempDir d;
  ecs::World w;
  load_gltf(w, write_scene(d, quad_gltf()));
  const auto& m = w.resource<SceneAssets>().materials.at(0);
  EXPECT_EQ(m.name, "plastic");
  EXPECT_FLOAT_EQ(m.base_color_factor.g, 0.25f);
  EXPECT_FLOAT_EQ(m.roughness_factor, 0.3f);
  EXPECT_FLOAT_EQ(m.metallic_factor, 0.0f);
  EXPECT_FLOAT_EQ(m.specular_factor, 0.0f) << "KHR_materials_specular factor 0 = pure Lambertian";
  EXPECT_FLOAT_EQ(m.emissive_strength, 5.0f);
  EXPECT_EQ(m.emission(), glm::vec3(5.0f, 2.5f, 0.0f));
  EXPECT_TRUE(m.double_sided);
}

TEST(GltfLoader, MissingNormalsAreGeneratedAndNonIndexedMeshesWork) {
  TempDir d;
  json j = quad_gltf();
  auto& prim = j["meshes"][0]["primitives"][0];
  prim["attributes"].erase("NORMAL");
  prim.erase("indices");
  j["accessors"][0]["count"] = 3;  // the first three vertices as one triangle
  j["accessors"][2]["count"] = 3;
  ecs::World w;
  load_gltf(w, write_scene(d, j));
  const auto& mesh = *w.resource<SceneAssets>().meshes[0];
  ASSERT_EQ(mesh.triangle_count(), 1u);
  for (const glm::vec3& n : mesh.normals) EXPECT_NEAR(glm::length(n - glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
}

TEST(GltfLoader, TriangleStripsAreTriangulated) {
  TempDir d;
  json j = quad_gltf();
  j["meshes"][0]["primitives"][0]["mode"] = 5;  // strip of 6 indices -> 4 triangles
  ecs::World w;
  load_gltf(w, write_scene(d, j));
  EXPECT_EQ(w.resource<SceneAssets>().meshes[0]->triangle_count(), 4u);
}

TEST(GltfLoader, NonUniformScaleIsBakedIntoAPrivateMesh) {
  TempDir d;
  json j = quad_gltf();
  j["nodes"][1]["scale"] = {1, 3, 1};
  ecs::World w;
  const auto r = load_gltf(w, write_scene(d, j));
  const auto& assets = w.resource<SceneAssets>();
  ASSERT_EQ(assets.meshes.size(), 2u);
  EXPECT_EQ(w.get<MeshInstance>(r.entities[1]).mesh, 1u);
  EXPECT_FLOAT_EQ(assets.meshes[1]->bounds_max.y, 3.0f);
  EXPECT_FLOAT_EQ(assets.meshes[0]->bounds_max.y, 1.0f) << "the shared asset is untouched";
}

TEST(GltfLoader, LightsPunctual) {
  TempDir d;
  json j = quad_gltf();
  j["extensionsUsed"] = {"KHR_lights_punctual"};
  j["extensions"]["KHR_lights_punctual"]["lights"] = json::parse(
      R"([{"type": "spot", "color": [1, 0.5, 0.25], "intensity": 100, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}])");
  j["nodes"][2]["extensions"]["KHR_lights_punctual"]["light"] = 0;
  ecs::World w;
  const auto r = load_gltf(w, write_scene(d, j));
  const PunctualLight& l = w.get<PunctualLight>(r.entities[2]);
  EXPECT_EQ(l.type, PunctualLight::Type::Spot);
  EXPECT_FLOAT_EQ(l.intensity, 100.0f);
  EXPECT_FLOAT_EQ(l.outer_cone_angle, 0.5f);
  EXPECT_EQ(l.color, glm::vec3(1, 0.5f, 0.25f));
}

// A directional light's disk: extras.angular_radius, read into the light and
// turned into the sampled disk's half-angle by the light set.
TEST(GltfLoader, ADirectionalLightsAngularRadiusComesFromItsExtras) {
  TempDir d;
  json j = quad_gltf();
  j["extensionsUsed"] = {"KHR_lights_punctual"};
  j["extensions"]["KHR_lights_punctual"]["lights"] =
      json::parse(R"([{"type": "directional", "intensity": 10, "extras": {"angular_radius": 0.045}}])");
  j["nodes"][2]["extensions"]["KHR_lights_punctual"]["light"] = 0;
  ecs::World w;
  const auto r = load_gltf(w, write_scene(d, j));
  EXPECT_FLOAT_EQ(w.get<PunctualLight>(r.entities[2]).angular_radius, 0.045f);
  const auto inst = render::punctual_instance(w.get<PunctualLight>(r.entities[2]), transform::Similarity{});
  ASSERT_TRUE(inst);
  EXPECT_FLOAT_EQ(inst->angular_radius, 0.045f) << "the light set samples a disk of that half-angle";
}

TEST(GltfLoaderBadInput, AnAngularRadiusOutOfRangeOrOnAPointLight) {
  TempDir d;
  const auto with_light = [&](const char* light) {
    json j = quad_gltf();
    j["extensionsUsed"] = {"KHR_lights_punctual"};
    j["extensions"]["KHR_lights_punctual"]["lights"] = json::array({json::parse(light)});
    j["nodes"][2]["extensions"]["KHR_lights_punctual"]["light"] = 0;
    return write_scene(d, j);
  };
  expect_rejected(with_light(R"({"type": "directional", "intensity": 1, "extras": {"angular_radius": 2}})"),
                  {"lights[0].extras.angular_radius", "[0, 0.5]"});
  expect_rejected(with_light(R"({"type": "point", "intensity": 1, "extras": {"angular_radius": 0.01}})"),
                  {"lights[0].extras.angular_radius", "directional lights only"});
}

TEST(GltfLoader, EnvironmentFromSceneExtras) {
  TempDir d;
  // 4x2 map: top row (v < 0.5, local +Y hemisphere) bright, bottom row dark.
  image::ImageRGB env(4, 2);
  for (int x = 0; x < 4; ++x) {
    env.at(x, 0) = glm::vec3(2.0f);
    env.at(x, 1) = glm::vec3(0.5f);
  }
  image::write_exr(d.path / "sky.exr", env);
  json j = quad_gltf();
  j["scenes"][0]["extras"]["environment"] = {{"uri", "sky.exr"}, {"strength", 3}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
  ecs::World w;
  load_gltf(w, write_scene(d, j));
  const auto& e = w.resource<SceneAssets>().environment;
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->radiance({0, 1, 0}), glm::vec3(6.0f)) << "+Y is the top row, times strength";
  EXPECT_EQ(e->radiance({0, -1, 0}), glm::vec3(1.5f));
}

// ---- bad input: each gets a clear error naming the file and the field ----------

TEST(GltfLoaderBadInput, MalformedJson) {
  TempDir d;
  std::ofstream(d.path / "broken.gltf") << "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [";
  expect_rejected(d.path / "broken.gltf", {"the JSON ends at line 1, column 41 (byte 40)", "truncated"});
  // A stray comma: where, and what the parser expected, without its exception's name.
  std::ofstream(d.path / "comma.gltf") << "{\"asset\": {\"version\": \"2.0\"},\n  , \"nodes\": []}";
  expect_rejected(d.path / "comma.gltf", {"JSON syntax error at line 2, column 3", "unexpected ','"});
  ecs::World w;
  try {
    load_gltf(w, d.path / "comma.gltf");
  } catch (const GltfError& e) {
    EXPECT_EQ(std::string(e.what()).find("json.exception"), std::string::npos) << e.what();
  }
}

TEST(GltfLoaderBadInput, AbsurdlyDeepJson) {
  TempDir d;
  std::ofstream(d.path / "deep.gltf") << std::string(100000, '[') << std::string(100000, ']');
  expect_rejected(d.path / "deep.gltf", {"nesting depth"});
}

TEST(GltfLoaderBadInput, AccessorPastItsBufferView) {
  TempDir d;
  json j = quad_gltf();
  j["accessors"][0]["count"] = 5;
  expect_rejected(write_scene(d, j), {"accessors[0]", "POSITION", "runs past the end of bufferViews[0]"});
}

TEST(GltfLoaderBadInput, BufferViewPastItsBuffer) {
  TempDir d;
  json j = quad_gltf();
  j["bufferViews"][3]["byteOffset"] = 132;  // 132 + 12 > 140
  expect_rejected(write_scene(d, j), {"bufferViews[3]", "runs past the end of buffers[0]"});
}

// Found by the gltf fuzzer (tests/fuzz/corpus/gltf/crash-image-buffer-view-past-bin-chunk.glb):
// tinygltf hands the image decoder a pointer at bufferView.byteOffset without
// checking it against the buffer, which read freed memory under ASan.
TEST(GltfLoaderBadInput, ImageBufferViewPastItsBuffer) {
  TempDir d;
  json j = quad_gltf();
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 92768}, {"byteLength", 2176}});
  j["images"] = json::array({{{"bufferView", j["bufferViews"].size() - 1}, {"mimeType", "image/png"}}});
  expect_rejected(write_scene(d, j), {"bufferViews[", "lie outside buffers[0], which holds 140 bytes", "images[0]"});
}

// Found by the glTF fuzzer (tests/fuzz/corpus/gltf/crash-image-view-past-byte-length.glb):
// the view lay inside the GLB's BIN chunk but past the buffer's declared
// byteLength, which is all tinygltf keeps, so the image decoder read past it.
TEST(GltfLoaderBadInput, ImageBufferViewInsideTheBinChunkButPastByteLength) {
  TempDir d;
  json j = quad_gltf();
  std::vector<unsigned char> bin = quad_bin();
  bin.resize(bin.size() + 60, 0);  // the chunk holds 200 bytes; the buffer declares 140
  j["buffers"] = json::array({{{"byteLength", 140}}});
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 128}, {"byteLength", 64}});
  j["images"] = json::array({{{"bufferView", j["bufferViews"].size() - 1}, {"mimeType", "image/png"}}});
  std::string text = j.dump();
  while (text.size() % 4) text += ' ';
  const auto u32 = [](std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  std::string glb = "glTF";
  u32(glb, 2);
  u32(glb, static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
  u32(glb, static_cast<std::uint32_t>(text.size()));
  glb += "JSON" + text;
  u32(glb, static_cast<std::uint32_t>(bin.size()));
  glb += std::string("BIN\0", 4);
  glb.append(reinterpret_cast<const char*>(bin.data()), bin.size());
  std::ofstream(d.path / "scene.glb", std::ios::binary) << glb;
  expect_rejected(d.path / "scene.glb", {"bufferViews[", "lie outside buffers[0], which holds 140 bytes", "images[0]"});
}

// Found by the image fuzzer (tests/fuzz/corpus/image/oom-png-chunk-claims-2gb.png):
// stb_image sized its IDAT buffer from the chunk's declared length, so a
// 489-byte PNG claiming 1.75 GB made it allocate that much.
TEST(GltfLoaderBadInput, PngChunkLongerThanTheFile) {
  TempDir d;
  const unsigned char png[] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A,                      // signature
                               0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 0, 0, 64, 0, 0, 0, 64, 8, 2, 0, 0, 0,
                               0x25, 0x0b, 0xe6, 0x89,                                         // IHDR + CRC
                               0x68, 0x65, 0x0a, 0x85, 'I', 'D', 'A', 'T', 1, 2, 3, 4, 5, 6};  // IDAT "1,751,452,293 bytes"
  std::ofstream(d.path / "bomb.png", std::ios::binary).write(reinterpret_cast<const char*>(png), sizeof png);
  json j = quad_gltf();
  j["images"] = json::array({{{"uri", "bomb.png"}}});
  expect_rejected(write_scene(d, j), {"images[0]", "PNG chunk 1 declares 1751452293 bytes but only 6 follow"});
}

TEST(GltfLoaderBadInput, IndexBeyondVertexCount) {
  TempDir d;
  auto bin = quad_bin();
  const std::uint16_t bad = 4;
  std::memcpy(bin.data() + 128 + 2, &bad, 2);
  expect_rejected(write_scene(d, quad_gltf(), bin), {"meshes[0].primitives[0].indices", ">= the vertex count 4"});
}

TEST(GltfLoaderBadInput, NanPosition) {
  TempDir d;
  expect_rejected(write_scene(d, quad_gltf(), quad_bin(4)), {"POSITION", "vertex 1", "not finite"});
}

TEST(GltfLoaderBadInput, MissingBufferFile) {
  TempDir d;
  json j = quad_gltf();
  j["buffers"][0]["uri"] = "nope.bin";
  expect_rejected(write_scene(d, j), {"buffers[0].uri", "nope.bin", "not found"});
}

TEST(GltfLoaderBadInput, UriOutsideTheSceneFolder) {
  TempDir d;
  fs::create_directories(d.path / "inner");
  const auto bin = quad_bin();
  std::ofstream(d.path / "outside.bin", std::ios::binary).write(reinterpret_cast<const char*>(bin.data()), 140);
  json j = quad_gltf();
  j["buffers"][0]["uri"] = "../outside.bin";
  std::ofstream(d.path / "inner" / "scene.gltf") << j.dump();
  expect_rejected(d.path / "inner" / "scene.gltf", {"buffers[0].uri", "outside"});
}

TEST(GltfLoaderBadInput, UriPointingAtADirectory) {
  TempDir d;
  fs::create_directories(d.path / "adir");
  json j = quad_gltf();
  j["buffers"][0]["uri"] = "adir";
  expect_rejected(write_scene(d, j), {"buffers[0].uri", "is a directory"});
}

TEST(GltfLoaderBadInput, UnsupportedRequiredExtension) {
  TempDir d;
  json j = quad_gltf();
  j["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  j["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  expect_rejected(write_scene(d, j), {"extensionsRequired", "KHR_draco_mesh_compression"});
}

TEST(GltfLoaderBadInput, NonTriangleMode) {
  TempDir d;
  json j = quad_gltf();
  j["meshes"][0]["primitives"][0]["mode"] = 1;  // LINES
  expect_rejected(write_scene(d, j), {"meshes[0].primitives[0].mode", "not a triangle mode"});
}

TEST(GltfLoaderBadInput, OutOfRangeMaterialFactor) {
  TempDir d;
  json j = quad_gltf();
  j["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = 1.5;
  expect_rejected(write_scene(d, j), {"materials[0].pbrMetallicRoughness.roughnessFactor", "outside [0"});
}

TEST(GltfLoaderBadInput, NodeCycle) {
  TempDir d;
  json j = quad_gltf();
  j["nodes"][1]["children"] = {0};
  expect_rejected(write_scene(d, j), {"nodes[0]", "reached twice"});
}

TEST(GltfLoaderBadInput, ImageThatIsNotPngOrJpeg) {
  TempDir d;
  std::ofstream(d.path / "tex.png") << "GIF89a definitely not a png";
  json j = quad_gltf();
  j["images"] = {{{"uri", "tex.png"}}};
  j["textures"] = {{{"source", 0}}};
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  expect_rejected(write_scene(d, j), {"images[0]", "magic bytes"});
}

TEST(GltfLoaderBadInput, TruncatedGlb) {
  TempDir d;
  const std::string body = quad_gltf().dump();
  std::vector<unsigned char> glb(12 + 8);
  std::memcpy(glb.data(), "glTF", 4);
  const std::uint32_t version = 2, total = 20 + 1000, chunk_len = 1000, chunk_type = 0x4E4F534A;
  std::memcpy(glb.data() + 4, &version, 4);
  std::memcpy(glb.data() + 8, &total, 4);
  std::memcpy(glb.data() + 12, &chunk_len, 4);
  std::memcpy(glb.data() + 16, &chunk_type, 4);
  glb.insert(glb.end(), body.begin(), body.begin() + 100);  // far less than the 1000 promised
  std::ofstream(d.path / "cut.glb", std::ios::binary).write(reinterpret_cast<const char*>(glb.data()),
                                                            static_cast<std::streamsize>(glb.size()));
  expect_rejected(d.path / "cut.glb", {"GLB"});
}

TEST(GltfLoaderBadInput, MissingSceneFileAndDirectory) {
  TempDir d;
  expect_rejected(d.path / "absent.gltf", {"file not found"});
  ecs::World w;
  EXPECT_THROW(load_gltf(w, d.path), GltfError);
}

TEST(GltfLoader, NodeExtrasThatAreSetBecomeMarkersWithTheWholeScale) {
  TempDir d;
  json j = quad_gltf();
  j["nodes"].push_back({{"name", "volume"}, {"translation", {1, 2, 3}}, {"scale", {2, 0.5, 4}},
                        {"extras", {{"some_volume", true}, {"off", false}, {"zero", 0}, {"weight", 2.5}, {"object", {{"dims", 8}}}, {"text", "x"}}}});
  j["scenes"][0]["nodes"].push_back(3);
  ecs::World w;
  const GltfLoadResult r = load_gltf(w, write_scene(d, j));
  const ecs::Entity e = r.entities.back();
  ASSERT_EQ(w.get<Name>(e).value, "volume");
  const NodeMarkers* m = w.try_get<NodeMarkers>(e);
  ASSERT_NE(m, nullptr);
  EXPECT_TRUE(m->has("some_volume"));
  EXPECT_TRUE(m->has("weight"));
  EXPECT_TRUE(m->has("object"));
  EXPECT_FALSE(m->has("off")) << "false is not set";
  EXPECT_FALSE(m->has("zero")) << "0 is not set";
  EXPECT_FALSE(m->has("text")) << "only true, non-zero numbers and objects mark";
  EXPECT_EQ(m->scale, glm::vec3(2.0f, 0.5f, 4.0f)) << "the non-uniform scale a Transform cannot hold";
  // Nodes without extras get none.
  EXPECT_EQ(w.try_get<NodeMarkers>(r.entities.front()), nullptr);
}
