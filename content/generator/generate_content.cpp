// Generates the bundled scenes deterministically (same bytes every run):
//   test_scenes/cornell_box/   Cornell box with an emissive area light
//   test_scenes/furnace/       a diffuse sphere under a uniform white sky
//   test_scenes/object_metal/  a glossy metal teapot-like object under a studio map
//   test_scenes/object_textured/ a textured diffuse object under the same map
//   test_scenes/thick_room/    a room of 0.3 m walls with mixed winding under
//                              double-sided materials, furniture, a striped
//                              wallpaper and a window onto a sky with a sun
//                              (issue 14's real-content problems, of our making)
//   levels/living_room/        the sample level: a room with a window lit by
//                              a sun (a directional light) and a sky map, a
//                              ceiling area light, large diffuse
//                              pieces, a glossy metal sphere, a mirror panel
//                              and a rough plastic object
//
//   content_generator --out DIR
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "engine/image/exr.h"
#include "engine/image/png.h"
#include "engine/math/sampling.h"
#include "engine/scene/environment.h"
#include "engine/scene/gltf_writer.h"
#include "engine/scene/procedural.h"
#include "engine/scene/sun.h"
#include "engine/scene/sun_extraction.h"

namespace {

using namespace engine;
using scene::GltfNodeDesc;
using scene::GltfSceneDesc;

material::Material diffuse(std::string name, glm::vec3 albedo) {
  material::Material m;
  m.name = std::move(name);
  m.base_color_factor = glm::vec4(albedo, 1.0f);
  m.metallic_factor = 0.0f;
  m.roughness_factor = 1.0f;
  m.specular_factor = 0.0f;  // pure Lambertian, as the converted Bitterli scenes
  m.specular_color_factor = glm::vec3(0.0f);
  m.double_sided = true;
  return m;
}
material::Material emitter(std::string name, glm::vec3 color, float strength) {
  material::Material m = diffuse(std::move(name), glm::vec3(0.0f));
  m.emissive_factor = color;
  m.emissive_strength = strength;
  return m;
}
material::Material metal(std::string name, glm::vec3 f0, float roughness) {
  material::Material m;
  m.name = std::move(name);
  m.base_color_factor = glm::vec4(f0, 1.0f);
  m.metallic_factor = 1.0f;
  m.roughness_factor = roughness;
  m.double_sided = true;
  return m;
}
material::Material plastic(std::string name, glm::vec3 albedo, float roughness) {
  material::Material m;
  m.name = std::move(name);
  m.base_color_factor = glm::vec4(albedo, 1.0f);
  m.metallic_factor = 0.0f;
  m.roughness_factor = roughness;
  m.double_sided = true;
  return m;
}

// Adds a mesh and a node placing it; returns the node index.
int add(GltfSceneDesc& s, scene::MeshAsset mesh, std::string name, glm::vec3 at, glm::quat rot = glm::quat(1, 0, 0, 0)) {
  mesh.name = name;
  s.meshes.push_back(std::move(mesh));
  GltfNodeDesc n;
  n.name = std::move(name);
  n.mesh = static_cast<int>(s.meshes.size() - 1);
  n.transform.translation = at;
  n.transform.rotation = rot;
  s.nodes.push_back(n);
  s.roots.push_back(static_cast<int>(s.nodes.size() - 1));
  return static_cast<int>(s.nodes.size() - 1);
}

void add_camera(GltfSceneDesc& s, glm::vec3 eye, glm::vec3 target, float yfov_degrees, float aspect) {
  GltfNodeDesc n;
  n.name = "Camera";
  n.transform.translation = eye;
  // Camera looks down its local -Z with +Y up.
  n.transform.rotation = glm::quatLookAtRH(glm::normalize(target - eye), glm::vec3(0, 1, 0));
  n.camera = scene::Camera{.yfov_radians = glm::radians(yfov_degrees), .aspect_ratio = aspect, .znear = 0.05f};
  s.nodes.push_back(n);
  s.roots.push_back(static_cast<int>(s.nodes.size() - 1));
}

scene::MeshAsset box(glm::vec3 half, std::uint32_t material) { return scene::make_box(half, false, material); }

// Four table legs sharing one mesh, standing at (x +- spread.x, z +- spread.y).
void add_table_legs(GltfSceneDesc& s, std::uint32_t material, float half_height, glm::vec2 centre, glm::vec2 spread) {
  scene::MeshAsset leg = box({0.03f, half_height, 0.03f}, material);
  leg.name = "TableLeg";
  s.meshes.push_back(leg);
  const int leg_mesh = static_cast<int>(s.meshes.size() - 1);
  for (int i = 0; i < 4; ++i) {
    GltfNodeDesc n;
    n.name = "TableLeg" + std::to_string(i);
    n.mesh = leg_mesh;
    n.transform.translation = {centre.x + (i % 2 ? spread.x : -spread.x), half_height, centre.y + (i / 2 ? spread.y : -spread.y)};
    s.nodes.push_back(n);
    s.roots.push_back(static_cast<int>(s.nodes.size() - 1));
  }
}

// ---- Cornell box ------------------------------------------------------------

GltfSceneDesc cornell_box() {
  GltfSceneDesc s;
  s.materials = {diffuse("White", {0.725f, 0.71f, 0.68f}), diffuse("Red", {0.63f, 0.065f, 0.05f}),
                 diffuse("Green", {0.14f, 0.45f, 0.091f}), emitter("Light", {1.0f, 0.706f, 0.235f}, 17.0f)};
  // Walls as thin slabs: floor, ceiling, back, left (red), right (green). The front is open.
  add(s, box({1.0f, 0.01f, 1.0f}, 0), "Floor", {0, -0.01f, 0});
  add(s, box({1.0f, 0.01f, 1.0f}, 0), "Ceiling", {0, 2.01f, 0});
  add(s, box({1.0f, 1.0f, 0.01f}, 0), "Back", {0, 1, -1.01f});
  add(s, box({0.01f, 1.0f, 1.0f}, 1), "Left", {-1.01f, 1, 0});
  add(s, box({0.01f, 1.0f, 1.0f}, 2), "Right", {1.01f, 1, 0});
  add(s, box({0.3f, 0.6f, 0.3f}, 0), "TallBox", {-0.33f, 0.6f, -0.29f}, glm::angleAxis(glm::radians(17.0f), glm::vec3(0, 1, 0)));
  add(s, box({0.3f, 0.3f, 0.3f}, 0), "ShortBox", {0.33f, 0.3f, 0.28f}, glm::angleAxis(glm::radians(-17.0f), glm::vec3(0, 1, 0)));
  scene::MeshAsset light = scene::make_quad({0.235f, 0.19f}, 3);
  for (auto& n : light.normals) n = {0, -1, 0};  // face down into the box
  for (auto& t : light.triangles) std::swap(t.y, t.z);
  add(s, light, "AreaLight", {0, 1.998f, 0});
  add_camera(s, {0, 1, 3.9f}, {0, 1, 0}, 39.3f, 1.0f);
  return s;
}

// ---- furnace ------------------------------------------------------------------

GltfSceneDesc furnace() {
  GltfSceneDesc s;
  s.materials = {diffuse("Albedo08", glm::vec3(0.8f))};
  add(s, scene::make_uv_sphere(1.0f, 96, 48, 0), "Sphere", {0, 0, 0});
  add_camera(s, {0, 0, 4}, {0, 0, 0}, 40.0f, 1.0f);
  s.environment = scene::GltfEnvironmentDesc{"white_sky.exr", 1.0f, glm::mat4(1.0f)};
  return s;
}

// ---- sky for the sample level ------------------------------------------------------

// A clear sky in the Mitsuba lat-long convention: blue zenith, pale horizon,
// dark ground and (with_disk) a small bright sun.
image::ImageRGB sky_map(glm::vec3 sun_dir, bool with_disk = true) {
  const int w = 256, h = 128;
  image::ImageRGB img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec3 d = scene::Environment::uv_to_direction({(static_cast<float>(x) + 0.5f) / static_cast<float>(w), (static_cast<float>(y) + 0.5f) / static_cast<float>(h)});
      glm::vec3 c;
      if (d.y >= 0) {
        const float t = std::pow(1.0f - d.y, 3.0f);
        c = glm::mix(glm::vec3(0.25f, 0.45f, 0.9f), glm::vec3(0.95f, 0.95f, 1.0f), t) * 1.2f;
      } else {
        c = glm::vec3(0.25f, 0.22f, 0.2f);
      }
      const float cos_sun = glm::dot(d, sun_dir);
      if (with_disk && cos_sun > std::cos(glm::radians(2.5f))) c += glm::vec3(2000.0f, 1800.0f, 1500.0f);
      img.at(x, y) = c;
    }
  return img;
}

// The sample level's sun as a directional light (KHR_lights_punctual), so a
// time-of-day control can turn it (engine/scene/sun.h): the light the sky
// map's disk would give, split out of that map exactly (its irradiance and
// power-weighted direction), while the level's sky.exr is written without
// the disk. Until 2026-11-24 the disk was in the map and the sun could only
// turn with the whole sky about the vertical.
void add_sun(GltfSceneDesc& s, glm::vec3 sun_dir) {
  const scene::SunSplit split = scene::split_sun(scene::Environment(sky_map(sun_dir, true), 1.0f, glm::mat4(1.0f)));
  if (!split.sun) throw std::runtime_error("the level's sky map has no sun to split out");
  const glm::vec3 e = split.sun->irradiance;
  const float peak = std::max(e.r, std::max(e.g, e.b));
  GltfNodeDesc n;
  n.name = "Sun";
  // A directional light shines along its local -z.
  const glm::vec2 angles = scene::sun_angles(glm::normalize(split.sun->direction));
  n.transform.rotation = scene::sun_rotation(angles.x, angles.y);
  n.light = scene::PunctualLight{.type = scene::PunctualLight::Type::Directional, .color = e / peak, .intensity = peak,
                                 .angular_radius = split.sun->angular_radius};  // the disk's soft shadow edge
  s.nodes.push_back(n);
  s.roots.push_back(static_cast<int>(s.nodes.size() - 1));
}

const glm::vec3 kLevelSun = glm::normalize(glm::vec3(1.0f, 0.55f, -0.25f));

GltfSceneDesc living_room() {
  GltfSceneDesc s;
  enum : std::uint32_t { Wall, Floor, Ceiling, Sofa, Wood, Rug, Gold, Mirror, BluePlastic, Lamp, Frame };
  s.materials = {diffuse("Walls", {0.75f, 0.72f, 0.66f}),      diffuse("Floor", {0.45f, 0.3f, 0.18f}),
                 diffuse("Ceiling", {0.85f, 0.85f, 0.85f}),    diffuse("Sofa", {0.3f, 0.38f, 0.5f}),
                 diffuse("TableWood", {0.35f, 0.2f, 0.1f}),    diffuse("Rug", {0.6f, 0.15f, 0.12f}),
                 metal("Gold", {1.0f, 0.78f, 0.34f}, 0.25f),   metal("Mirror", {0.95f, 0.95f, 0.95f}, 0.02f),
                 plastic("BluePlastic", {0.08f, 0.3f, 0.7f}, 0.45f), emitter("CeilingLamp", {1.0f, 0.9f, 0.75f}, 12.0f),
                 diffuse("MirrorFrame", {0.1f, 0.1f, 0.1f})};
  // Room interior: x in [-3, 3], y in [0, 3], z in [-2.5, 2.5]; walls 0.1 thick.
  add(s, box({3.1f, 0.05f, 2.6f}, Floor), "Floor", {0, -0.05f, 0});
  add(s, box({3.1f, 0.05f, 2.6f}, Ceiling), "Ceiling", {0, 3.05f, 0});
  add(s, box({3.1f, 1.5f, 0.05f}, Wall), "BackWall", {0, 1.5f, -2.55f});
  add(s, box({3.1f, 1.5f, 0.05f}, Wall), "FrontWall", {0, 1.5f, 2.55f});
  add(s, box({0.05f, 1.5f, 2.6f}, Wall), "LeftWall", {-3.05f, 1.5f, 0});
  // Right wall (+X) with a window: z in [-1.4, 0.6], y in [0.8, 2.5].
  add(s, box({0.05f, 0.4f, 2.6f}, Wall), "RightWallBelow", {3.05f, 0.4f, 0});
  add(s, box({0.05f, 0.25f, 2.6f}, Wall), "RightWallAbove", {3.05f, 2.75f, 0});
  add(s, box({0.05f, 0.85f, 0.55f}, Wall), "RightWallBack", {3.05f, 1.65f, -1.95f});
  add(s, box({0.05f, 0.85f, 0.95f}, Wall), "RightWallFront", {3.05f, 1.65f, 1.55f});
  // Furniture.
  add(s, box({1.1f, 0.22f, 0.45f}, Sofa), "SofaSeat", {-1.6f, 0.22f, -1.9f});
  add(s, box({1.1f, 0.4f, 0.12f}, Sofa), "SofaBack", {-1.6f, 0.62f, -2.33f});
  add(s, box({1.6f, 0.01f, 1.1f}, Rug), "Rug", {-0.4f, 0.01f, -0.6f});
  add(s, box({0.7f, 0.03f, 0.45f}, Wood), "TableTop", {-0.4f, 0.5f, -0.6f});
  add_table_legs(s, Wood, 0.235f, {-0.4f, -0.6f}, {0.62f, 0.38f});
  add(s, scene::make_uv_sphere(0.18f, 48, 24, Gold), "GoldSphere", {-0.6f, 0.71f, -0.55f});
  add(s, box({0.2f, 0.2f, 0.2f}, BluePlastic), "PlasticCube", {1.4f, 0.2f, 0.4f},
      glm::angleAxis(glm::radians(30.0f), glm::vec3(0, 1, 0)));
  add(s, scene::make_uv_sphere(0.25f, 48, 24, BluePlastic), "PlasticBall", {1.0f, 0.25f, -1.3f});
  // Mirror panel on the left wall, in a dark frame.
  add(s, box({0.02f, 0.75f, 0.55f}, Frame), "MirrorFrame", {-2.98f, 1.5f, 0.3f});
  add(s, box({0.01f, 0.7f, 0.5f}, Mirror), "MirrorPanel", {-2.95f, 1.5f, 0.3f});
  // Ceiling lamp: an emissive panel facing down.
  scene::MeshAsset lamp = scene::make_quad({0.3f, 0.3f}, Lamp);
  for (auto& n : lamp.normals) n = {0, -1, 0};
  for (auto& t : lamp.triangles) std::swap(t.y, t.z);
  add(s, lamp, "CeilingLamp", {0.0f, 2.99f, 0.0f});
  add_camera(s, {-2.4f, 1.6f, 2.2f}, {0.6f, 0.9f, -0.9f}, 60.0f, 16.0f / 9.0f);
  add_sun(s, kLevelSun);
  s.environment = scene::GltfEnvironmentDesc{"sky.exr", 1.0f, glm::mat4(1.0f)};
  return s;
}

// ---- object-scale scenes (the paper's Fig. 7 setting) ----------------------------

// A studio-like environment: dim gradient plus two soft key lights, smooth
// enough that degree-4 SH can represent most of it.
image::ImageRGB studio_map() {
  const int w = 128, h = 64;
  image::ImageRGB img(w, h);
  const glm::vec3 key = glm::normalize(glm::vec3(0.6f, 0.7f, 0.4f)), fill = glm::normalize(glm::vec3(-0.7f, 0.3f, -0.5f));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec3 d = scene::Environment::uv_to_direction({(static_cast<float>(x) + 0.5f) / static_cast<float>(w),
                                                               (static_cast<float>(y) + 0.5f) / static_cast<float>(h)});
      glm::vec3 c = glm::mix(glm::vec3(0.05f, 0.05f, 0.06f), glm::vec3(0.35f, 0.4f, 0.5f), 0.5f + 0.5f * d.y);
      c += glm::vec3(6.0f, 5.5f, 5.0f) * std::pow(std::max(0.0f, glm::dot(d, key)), 24.0f);
      c += glm::vec3(1.2f, 1.4f, 2.0f) * std::pow(std::max(0.0f, glm::dot(d, fill)), 8.0f);
      img.at(x, y) = c;
    }
  return img;
}

// A teapot-like object: body, lid knob, spout and handle, so it shadows and
// reflects itself.
scene::MeshAsset teapot_like(std::uint32_t material) {
  scene::MeshAsset body = scene::make_uv_sphere(0.5f, 64, 32, material);
  for (auto& p : body.positions) p.y *= 0.8f;
  for (auto& n : body.normals) n = glm::normalize(glm::vec3(n.x, n.y / 0.8f, n.z));
  scene::MeshAsset knob = scene::make_uv_sphere(0.08f, 16, 8, material);
  for (auto& p : knob.positions) p.y += 0.44f;
  scene::append_mesh(body, knob);
  scene::MeshAsset spout = scene::make_tube(0.09f, 0.45f, 24, 0.5f, material);
  const glm::quat tilt = glm::angleAxis(glm::radians(-50.0f), glm::vec3(0, 0, 1));
  for (auto& p : spout.positions) p = tilt * p + glm::vec3(0.38f, -0.05f, 0);
  for (auto& n : spout.normals) n = tilt * n;
  scene::append_mesh(body, spout);
  scene::MeshAsset handle = scene::make_torus(0.2f, 0.04f, 48, 12, material);
  const glm::quat stand = glm::angleAxis(glm::radians(90.0f), glm::vec3(1, 0, 0));
  for (auto& p : handle.positions) p = stand * p + glm::vec3(-0.5f, 0.02f, 0);
  for (auto& n : handle.normals) n = stand * n;
  scene::append_mesh(body, handle);
  body.name = "Teapot";
  return body;
}

GltfSceneDesc object_metal() {
  GltfSceneDesc s;
  s.materials = {metal("GlossyCopper", {0.95f, 0.64f, 0.54f}, 0.3f)};
  add(s, teapot_like(0), "Teapot", {0, 0, 0});
  add_camera(s, {0.2f, 0.6f, 2.3f}, {0, 0, 0}, 40.0f, 1.0f);
  s.environment = scene::GltfEnvironmentDesc{"studio.exr", 1.0f, glm::mat4(1.0f)};
  return s;
}

GltfSceneDesc object_textured() {
  GltfSceneDesc s;
  material::Material m = diffuse("CheckerDiffuse", glm::vec3(1.0f));
  m.base_color_texture = 0;
  s.materials = {m};
  s.images = {"checker.png"};
  scene::MeshAsset vase = scene::make_uv_sphere(0.45f, 64, 32, 0);
  scene::MeshAsset ring = scene::make_torus(0.42f, 0.12f, 64, 16, 0);
  for (auto& p : ring.positions) p.y += 0.3f;
  scene::append_mesh(vase, ring);
  vase.name = "TexturedVase";
  add(s, vase, "TexturedVase", {0, 0, 0});
  add_camera(s, {0.3f, 0.8f, 2.2f}, {0, 0.05f, 0}, 40.0f, 1.0f);
  s.environment = scene::GltfEnvironmentDesc{"studio.exr", 1.0f, glm::mat4(1.0f)};
  return s;
}

// ---- thick-walled room (issue 14) -----------------------------------------------------

// Fine stripes of two tones, 4 texels wide, 256 texels across a 4-5 m wall: a
// pixel of a 320x180 view covers several stripes.
image::Rgb8Image wallpaper_texture() {
  image::Rgb8Image img(256, 256);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      const bool on = ((x / 4) % 2) == 0;
      std::uint8_t* p = img.at(x, y);
      p[0] = on ? 235 : 150;
      p[1] = on ? 225 : 120;
      p[2] = on ? 205 : 95;
    }
  return img;
}

GltfSceneDesc thick_room() {
  GltfSceneDesc s;
  enum : std::uint32_t { Paper, Floor, Ceiling, Wood, Fabric };
  material::Material paper = diffuse("Wallpaper", glm::vec3(1.0f));
  paper.base_color_texture = 0;
  s.materials = {paper, diffuse("Floor", {0.55f, 0.42f, 0.3f}), diffuse("Ceiling", {0.9f, 0.9f, 0.88f}),
                 diffuse("Wood", {0.4f, 0.25f, 0.14f}), diffuse("Fabric", {0.3f, 0.45f, 0.35f})};
  s.images = {"wallpaper.png"};
  // Interior x in [-2.5, 2.5], y in [0, 2.8], z in [-2, 2]; walls, floor and
  // ceiling 0.3 m thick. Mixed winding, as in much real content: the ceiling,
  // the back wall and the left wall face into their own solids (inward
  // boxes), so from the room one sees their back faces; all materials are
  // double-sided.
  const float t = 0.15f;
  auto slab = [&](glm::vec3 half, std::uint32_t m, bool flipped) { return scene::make_box(half, flipped, m); };
  add(s, slab({2.5f + 2 * t, t, 2 + 2 * t}, Floor, false), "Floor", {0, -t, 0});
  add(s, slab({2.5f + 2 * t, t, 2 + 2 * t}, Ceiling, true), "Ceiling", {0, 2.8f + t, 0});
  add(s, slab({2.5f, 1.4f, t}, Paper, true), "BackWall", {0, 1.4f, -2 - t});
  add(s, slab({2.5f, 1.4f, t}, Paper, false), "FrontWall", {0, 1.4f, 2 + t});
  add(s, slab({t, 1.4f, 2 + 2 * t}, Paper, true), "LeftWall", {-2.5f - t, 1.4f, 0});
  // Right wall (+x) around a window: z in [-0.9, 0.9], y in [0.9, 2.2].
  add(s, slab({t, 0.45f, 2 + 2 * t}, Paper, false), "RightWallBelow", {2.5f + t, 0.45f, 0});
  add(s, slab({t, 0.3f, 2 + 2 * t}, Paper, false), "RightWallAbove", {2.5f + t, 2.5f, 0});
  add(s, slab({t, 0.65f, 0.55f + t}, Paper, false), "RightWallBack", {2.5f + t, 1.55f, -1.45f - t});
  add(s, slab({t, 0.65f, 0.55f + t}, Paper, false), "RightWallFront", {2.5f + t, 1.55f, 1.45f + t});
  // Furniture: a table, a shelf against the back wall, a sofa.
  add(s, box({0.6f, 0.03f, 0.4f}, Wood), "TableTop", {0.2f, 0.72f, 0.1f});
  add_table_legs(s, Wood, 0.345f, {0.2f, 0.1f}, {0.54f, 0.34f});
  add(s, box({0.9f, 0.9f, 0.2f}, Wood), "Shelf", {-1.2f, 0.9f, -1.8f});
  add(s, box({0.4f, 0.25f, 1.0f}, Fabric), "SofaSeat", {-2.05f, 0.25f, 0.4f});
  add(s, box({0.12f, 0.45f, 1.0f}, Fabric), "SofaBack", {-2.38f, 0.65f, 0.4f});
  add_camera(s, {-1.9f, 1.6f, 1.7f}, {1.0f, 0.9f, -1.2f}, 60.0f, 16.0f / 9.0f);
  s.environment = scene::GltfEnvironmentDesc{"sky.exr", 1.0f, glm::mat4(1.0f)};
  return s;
}

image::Rgb8Image checker_texture() {
  image::Rgb8Image img(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool on = ((x / 8) + (y / 8)) % 2 == 0;
      std::uint8_t* p = img.at(x, y);
      p[0] = on ? 220 : 40;
      p[1] = on ? 180 : 90;
      p[2] = on ? 60 : 160;
    }
  return img;
}

int usage() {
  std::fprintf(stderr, "usage: content_generator --out DIR\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 || std::string(argv[1]) != "--out") return usage();
  const std::filesystem::path out = argv[2];
  try {
    scene::write_gltf(out / "test_scenes/cornell_box/scene.gltf", cornell_box());
    image::write_exr(out / "test_scenes/furnace/white_sky.exr", image::ImageRGB(8, 4, glm::vec3(1.0f)), image::ExrPixelType::Half);
    scene::write_gltf(out / "test_scenes/furnace/scene.gltf", furnace());
    image::write_exr(out / "levels/living_room/sky.exr", sky_map(kLevelSun, false), image::ExrPixelType::Half);
    scene::write_gltf(out / "levels/living_room/scene.gltf", living_room());
    for (const char* dir : {"test_scenes/object_metal", "test_scenes/object_textured"})
      image::write_exr(out / dir / "studio.exr", studio_map(), image::ExrPixelType::Half);
    scene::write_gltf(out / "test_scenes/object_metal/scene.gltf", object_metal());
    image::write_png(out / "test_scenes/object_textured/checker.png", checker_texture());
    scene::write_gltf(out / "test_scenes/object_textured/scene.gltf", object_textured());
    image::write_exr(out / "test_scenes/thick_room/sky.exr", sky_map(glm::normalize(glm::vec3(1.0f, 0.6f, 0.3f))), image::ExrPixelType::Half);
    image::write_png(out / "test_scenes/thick_room/wallpaper.png", wallpaper_texture());
    scene::write_gltf(out / "test_scenes/thick_room/scene.gltf", thick_room());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "content_generator: %s\n", e.what());
    return 1;
  }
  std::printf("content written to %s\n", out.string().c_str());
  return 0;
}
