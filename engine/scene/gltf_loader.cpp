#include "engine/scene/gltf_loader.h"

#include <tiny_gltf.h>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/gtx/matrix_decompose.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "engine/image/exr.h"
#include "engine/scene/components.h"
#include "engine/scene/gltf_accessor.h"
#include "engine/scene/gltf_guard.h"
#include "engine/scene/scene_assets.h"
#include "engine/transform/transform.h"

namespace engine::scene {

namespace fs = std::filesystem;
using namespace gltf_detail;

namespace {

const std::set<std::string> kSupportedExtensions = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                                     "KHR_materials_specular"};

struct Context {
  std::string file;  // file name used in messages
  fs::path dir;
  const tinygltf::Model& model;
  const GltfLoadOptions& options;
  GltfLoadResult& result;

  [[noreturn]] void fail(const std::string& field, const std::string& why) const {
    throw GltfError(file + ": " + field + ": " + why);
  }
  void warn(const std::string& field, const std::string& why) const { result.warnings.push_back(file + ": " + field + ": " + why); }
};

std::string idx(const char* array, std::size_t i) { return std::string(array) + "[" + std::to_string(i) + "]"; }

// ---- numbers -------------------------------------------------------------

float finite_in_range(const Context& c, const std::string& field, double v, double lo, double hi) {
  if (!std::isfinite(v)) c.fail(field, "value is not finite");
  if (v < lo || v > hi)
    c.fail(field, "value " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<float>(v);
}

template <int N>
glm::vec<N, float> vec_in_range(const Context& c, const std::string& field, const std::vector<double>& v, double lo,
                                double hi) {
  if (v.size() != N) c.fail(field, "expected " + std::to_string(N) + " numbers, got " + std::to_string(v.size()));
  glm::vec<N, float> out;
  for (int i = 0; i < N; ++i)
    out[i] = finite_in_range(c, field + "[" + std::to_string(i) + "]", v[static_cast<std::size_t>(i)], lo, hi);
  return out;
}

double value_number(const Context& c, const tinygltf::Value& v, const std::string& field) {
  if (!v.IsNumber()) c.fail(field, "must be a number");
  return v.GetNumberAsDouble();
}

// ---- materials and textures ---------------------------------------------

std::int32_t texture_ref(const Context& c, const std::string& field, int index, int tex_coord) {
  if (index < 0) return material::kNoTexture;
  if (static_cast<std::size_t>(index) >= c.model.textures.size())
    c.fail(field + ".index", "texture " + std::to_string(index) + " is out of range (" +
                                 std::to_string(c.model.textures.size()) + " textures)");
  if (tex_coord != 0) c.fail(field + ".texCoord", "only TEXCOORD_0 is supported, got " + std::to_string(tex_coord));
  return index;
}

Wrap wrap_mode(int gl) {
  switch (gl) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Wrap::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Wrap::MirroredRepeat;
    default: return Wrap::Repeat;
  }
}

std::vector<Texture> load_textures(const Context& c) {
  std::vector<Texture> out;
  for (std::size_t i = 0; i < c.model.textures.size(); ++i) {
    const tinygltf::Texture& t = c.model.textures[i];
    const std::string field = idx("textures", i);
    if (t.source < 0 || static_cast<std::size_t>(t.source) >= c.model.images.size())
      c.fail(field + ".source", "image " + std::to_string(t.source) + " is out of range (" +
                                    std::to_string(c.model.images.size()) + " images)");
    const tinygltf::Image& img = c.model.images[static_cast<std::size_t>(t.source)];
    if (img.image.size() != static_cast<std::size_t>(img.width) * img.height * 4)
      c.fail(idx("images", static_cast<std::size_t>(t.source)), "image data was not decoded");
    Texture tex;
    tex.name = img.name.empty() ? img.uri : img.name;
    tex.width = img.width;
    tex.height = img.height;
    tex.rgba = img.image;
    if (t.sampler >= 0) {
      if (static_cast<std::size_t>(t.sampler) >= c.model.samplers.size())
        c.fail(field + ".sampler", "sampler " + std::to_string(t.sampler) + " is out of range");
      const tinygltf::Sampler& s = c.model.samplers[static_cast<std::size_t>(t.sampler)];
      tex.wrap_s = wrap_mode(s.wrapS);
      tex.wrap_t = wrap_mode(s.wrapT);
    }
    out.push_back(std::move(tex));
  }
  return out;
}

std::vector<material::Material> load_materials(const Context& c) {
  std::vector<material::Material> out;
  for (std::size_t i = 0; i < c.model.materials.size(); ++i) {
    const tinygltf::Material& m = c.model.materials[i];
    const std::string f = idx("materials", i);
    const auto& pbr = m.pbrMetallicRoughness;
    material::Material mat;
    mat.name = m.name.empty() ? f : m.name;
    mat.base_color_factor = vec_in_range<4>(c, f + ".pbrMetallicRoughness.baseColorFactor", pbr.baseColorFactor, 0, 1);
    mat.base_color_texture = texture_ref(c, f + ".pbrMetallicRoughness.baseColorTexture", pbr.baseColorTexture.index,
                                         pbr.baseColorTexture.texCoord);
    mat.metallic_factor = finite_in_range(c, f + ".pbrMetallicRoughness.metallicFactor", pbr.metallicFactor, 0, 1);
    mat.roughness_factor = finite_in_range(c, f + ".pbrMetallicRoughness.roughnessFactor", pbr.roughnessFactor, 0, 1);
    mat.metallic_roughness_texture =
        texture_ref(c, f + ".pbrMetallicRoughness.metallicRoughnessTexture", pbr.metallicRoughnessTexture.index,
                    pbr.metallicRoughnessTexture.texCoord);
    mat.emissive_factor = vec_in_range<3>(c, f + ".emissiveFactor", m.emissiveFactor, 0, 1);
    mat.emissive_texture = texture_ref(c, f + ".emissiveTexture", m.emissiveTexture.index, m.emissiveTexture.texCoord);
    if (m.alphaMode == "MASK") mat.alpha_mode = material::AlphaMode::Mask;
    else if (m.alphaMode == "BLEND") {
      mat.alpha_mode = material::AlphaMode::Blend;
      c.warn(f + ".alphaMode", "BLEND is rendered as OPAQUE");
    } else if (m.alphaMode != "OPAQUE" && !m.alphaMode.empty())
      c.fail(f + ".alphaMode", "must be OPAQUE, MASK or BLEND, got '" + m.alphaMode + "'");
    mat.alpha_cutoff = finite_in_range(c, f + ".alphaCutoff", m.alphaCutoff, 0, 1e30);
    mat.double_sided = m.doubleSided;

    if (auto it = m.extensions.find("KHR_materials_emissive_strength"); it != m.extensions.end()) {
      const std::string ef = f + ".extensions.KHR_materials_emissive_strength.emissiveStrength";
      if (it->second.Has("emissiveStrength"))
        mat.emissive_strength = finite_in_range(c, ef, value_number(c, it->second.Get("emissiveStrength"), ef), 0, 1e30);
    }
    if (auto it = m.extensions.find("KHR_materials_specular"); it != m.extensions.end()) {
      const std::string sf = f + ".extensions.KHR_materials_specular";
      const tinygltf::Value& ext = it->second;
      if (ext.Has("specularFactor"))
        mat.specular_factor = finite_in_range(c, sf + ".specularFactor",
                                              value_number(c, ext.Get("specularFactor"), sf + ".specularFactor"), 0, 1);
      if (ext.Has("specularColorFactor")) {
        const tinygltf::Value& col = ext.Get("specularColorFactor");
        if (!col.IsArray() || col.ArrayLen() != 3) c.fail(sf + ".specularColorFactor", "must be an array of 3 numbers");
        for (int k = 0; k < 3; ++k) {
          const std::string kf = sf + ".specularColorFactor[" + std::to_string(k) + "]";
          mat.specular_color_factor[k] = finite_in_range(c, kf, value_number(c, col.Get(k), kf), 0, 1e30);
        }
      }
      if (ext.Has("specularTexture") || ext.Has("specularColorTexture"))
        c.warn(sf, "specular textures are ignored; the factors are used");
    }
    out.push_back(std::move(mat));
  }
  // Primitives without a material use the glTF default material, kept last.
  material::Material def;
  def.name = "glTF default material";
  out.push_back(def);
  return out;
}

// ---- meshes ---------------------------------------------------------------

// Triangle list from a primitive's index stream (or 0..n-1) and its mode.
std::vector<glm::uvec3> triangulate(const Context& c, const std::string& f, const std::vector<std::uint32_t>& idx_in,
                                    int mode) {
  std::vector<glm::uvec3> tris;
  const std::size_t n = idx_in.size();
  switch (mode) {
    case TINYGLTF_MODE_TRIANGLES:
      if (n % 3 != 0) c.fail(f, "TRIANGLES needs a multiple of 3 indices, got " + std::to_string(n));
      for (std::size_t i = 0; i + 2 < n; i += 3) tris.emplace_back(idx_in[i], idx_in[i + 1], idx_in[i + 2]);
      break;
    case TINYGLTF_MODE_TRIANGLE_STRIP:
      for (std::size_t i = 0; i + 2 < n; ++i)
        tris.push_back(i % 2 == 0 ? glm::uvec3(idx_in[i], idx_in[i + 1], idx_in[i + 2])
                                  : glm::uvec3(idx_in[i + 1], idx_in[i], idx_in[i + 2]));
      break;
    case TINYGLTF_MODE_TRIANGLE_FAN:
      for (std::size_t i = 1; i + 1 < n; ++i) tris.emplace_back(idx_in[0], idx_in[i], idx_in[i + 1]);
      break;
    default:
      c.fail(f + ".mode", "mode " + std::to_string(mode) +
                              " is not a triangle mode (only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN are supported)");
  }
  return tris;
}

MeshAsset load_mesh(const Context& c, const AccessorReader& reader, std::size_t mesh_index, std::uint32_t default_material) {
  const tinygltf::Mesh& mesh = c.model.meshes[mesh_index];
  const std::string mf = idx("meshes", mesh_index);
  MeshAsset out;
  out.name = mesh.name.empty() ? mf : mesh.name;
  bool any_missing_normals = false, any_uvs = false, any_missing_uvs = false;
  for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
    const tinygltf::Primitive& prim = mesh.primitives[p];
    const std::string pf = mf + ".primitives[" + std::to_string(p) + "]";
    auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) c.fail(pf + ".attributes", "POSITION is required");
    const std::vector<glm::vec3> pos = reader.vec3(pos_it->second, pf + ".attributes.POSITION");
    for (std::size_t v = 0; v < pos.size(); ++v)
      if (!std::isfinite(pos[v].x) || !std::isfinite(pos[v].y) || !std::isfinite(pos[v].z))
        c.fail(pf + ".attributes.POSITION", "vertex " + std::to_string(v) + " is not finite (NaN or Inf)");

    std::vector<glm::vec3> nrm;
    if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
      nrm = reader.vec3(it->second, pf + ".attributes.NORMAL");
      if (nrm.size() != pos.size()) c.fail(pf + ".attributes.NORMAL", "count differs from POSITION's");
      for (std::size_t v = 0; v < nrm.size(); ++v)
        if (!std::isfinite(nrm[v].x) || !std::isfinite(nrm[v].y) || !std::isfinite(nrm[v].z))
          c.fail(pf + ".attributes.NORMAL", "vertex " + std::to_string(v) + " is not finite (NaN or Inf)");
    } else {
      any_missing_normals = true;
    }
    std::vector<glm::vec2> uv;
    if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
      uv = reader.vec2(it->second, pf + ".attributes.TEXCOORD_0");
      if (uv.size() != pos.size()) c.fail(pf + ".attributes.TEXCOORD_0", "count differs from POSITION's");
      any_uvs = true;
    } else {
      any_missing_uvs = true;
    }

    std::vector<std::uint32_t> indices;
    if (prim.indices >= 0) {
      indices = reader.indices(prim.indices, pf + ".indices");
      for (std::size_t k = 0; k < indices.size(); ++k)
        if (indices[k] >= pos.size())
          c.fail(pf + ".indices", "index " + std::to_string(indices[k]) + " at position " + std::to_string(k) +
                                      " is >= the vertex count " + std::to_string(pos.size()));
    } else {
      indices.resize(pos.size());
      for (std::size_t k = 0; k < indices.size(); ++k) indices[k] = static_cast<std::uint32_t>(k);
    }
    const std::vector<glm::uvec3> tris = triangulate(c, pf, indices, prim.mode);

    std::uint32_t material = default_material;
    if (prim.material >= 0) {
      if (static_cast<std::size_t>(prim.material) >= c.model.materials.size())
        c.fail(pf + ".material", "material " + std::to_string(prim.material) + " is out of range (" +
                                     std::to_string(c.model.materials.size()) + " materials)");
      material = static_cast<std::uint32_t>(prim.material);
    }

    const auto base = static_cast<std::uint32_t>(out.positions.size());
    if (out.positions.size() + pos.size() >= 0xffffffffull) c.fail(mf, "too many vertices");
    out.positions.insert(out.positions.end(), pos.begin(), pos.end());
    if (nrm.empty()) nrm.assign(pos.size(), glm::vec3(0.0f));
    out.normals.insert(out.normals.end(), nrm.begin(), nrm.end());
    if (uv.empty()) uv.assign(pos.size(), glm::vec2(0.0f));
    out.uvs.insert(out.uvs.end(), uv.begin(), uv.end());
    for (const glm::uvec3& t : tris) {
      out.triangles.push_back(t + glm::uvec3(base));
      out.triangle_material.push_back(material);
    }
  }
  if (any_missing_uvs && any_uvs) c.warn(mf, "some primitives lack TEXCOORD_0; they use (0, 0)");
  if (!any_uvs) out.uvs.clear();
  if (any_missing_normals) {
    // Generate for the whole mesh, then keep the authored normals where present.
    MeshAsset generated = out;
    generated.generate_normals();
    for (std::size_t v = 0; v < out.normals.size(); ++v)
      if (out.normals[v] == glm::vec3(0.0f)) out.normals[v] = generated.normals[v];
  }
  for (glm::vec3& n : out.normals) {
    const float len = glm::length(n);
    n = len > 1e-12f ? n / len : glm::vec3(0, 0, 1);
  }
  out.compute_bounds();
  return out;
}

// ---- nodes ------------------------------------------------------------------

struct NodeTransform {
  transform::Transform local;
  glm::vec3 residual_scale{1.0f};  // non-uniform (or mirroring) part to bake into the mesh
  bool needs_bake = false;
};

NodeTransform node_transform(const Context& c, std::size_t i) {
  const tinygltf::Node& n = c.model.nodes[i];
  const std::string f = idx("nodes", i);
  glm::vec3 t(0.0f), s(1.0f);
  glm::quat r(1, 0, 0, 0);
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16) c.fail(f + ".matrix", "must have 16 numbers");
    glm::mat4 m;
    for (int k = 0; k < 16; ++k) {
      const double v = n.matrix[static_cast<std::size_t>(k)];
      if (!std::isfinite(v)) c.fail(f + ".matrix", "element " + std::to_string(k) + " is not finite");
      glm::value_ptr(m)[k] = static_cast<float>(v);
    }
    glm::vec3 skew;
    glm::vec4 persp;
    if (!glm::decompose(m, s, r, t, skew, persp)) c.fail(f + ".matrix", "is singular");
    if (glm::length(skew) > 1e-4f) c.fail(f + ".matrix", "has shear, which is not supported");
    r = glm::conjugate(r);  // glm::decompose returns the conjugate in GLM 0.9.9
  } else {
    if (!n.translation.empty()) t = vec_in_range<3>(c, f + ".translation", n.translation, -1e30, 1e30);
    if (!n.rotation.empty()) {
      const glm::vec4 q = vec_in_range<4>(c, f + ".rotation", n.rotation, -1.01, 1.01);
      r = glm::normalize(glm::quat(q.w, q.x, q.y, q.z));
    }
    if (!n.scale.empty()) s = vec_in_range<3>(c, f + ".scale", n.scale, -1e30, 1e30);
  }
  NodeTransform out;
  out.local.translation = t;
  out.local.rotation = r;
  const float mean = (std::abs(s.x) + std::abs(s.y) + std::abs(s.z)) / 3.0f;
  if (mean <= 0) c.fail(f + ".scale", "scale is zero");
  const bool uniform = std::abs(std::abs(s.x) - mean) <= 1e-4f * mean && std::abs(std::abs(s.y) - mean) <= 1e-4f * mean &&
                       std::abs(std::abs(s.z) - mean) <= 1e-4f * mean && s.x > 0 && s.y > 0 && s.z > 0;
  out.local.scale = uniform ? mean : 1.0f;
  if (!uniform) {
    out.needs_bake = true;
    out.residual_scale = s;
  }
  return out;
}

// A private copy of a mesh with a non-uniform (or mirroring) scale baked in.
MeshAsset bake_scale(const MeshAsset& src, glm::vec3 s) {
  MeshAsset m = src;
  m.name += " (scaled)";
  for (glm::vec3& p : m.positions) p *= s;
  for (glm::vec3& n : m.normals) n = glm::normalize(n / s);
  if (s.x * s.y * s.z < 0)
    for (glm::uvec3& t : m.triangles) std::swap(t.y, t.z);
  m.compute_bounds();
  return m;
}

// ---- environment --------------------------------------------------------------

std::optional<Environment> load_environment(const Context& c, const FileAccess& access, std::size_t scene_index) {
  const tinygltf::Value& extras = c.model.scenes[scene_index].extras;
  const std::string f = idx("scenes", scene_index) + ".extras.environment";
  if (!extras.IsObject() || !extras.Has("environment")) return std::nullopt;
  const tinygltf::Value& env = extras.Get("environment");
  if (!env.IsObject()) c.fail(f, "must be an object {uri, strength, matrix}");
  if (!env.Has("uri") || !env.Get("uri").IsString()) c.fail(f + ".uri", "must be a string");
  const std::string uri = env.Get("uri").Get<std::string>();
  float strength = 1.0f;
  if (env.Has("strength"))
    strength = finite_in_range(c, f + ".strength", value_number(c, env.Get("strength"), f + ".strength"), 0, 1e30);
  glm::mat4 matrix(1.0f);
  if (env.Has("matrix")) {
    const tinygltf::Value& m = env.Get("matrix");
    if (!m.IsArray() || m.ArrayLen() != 16) c.fail(f + ".matrix", "must be an array of 16 numbers");
    for (int k = 0; k < 16; ++k) {
      const std::string kf = f + ".matrix[" + std::to_string(k) + "]";
      glm::value_ptr(matrix)[k] = finite_in_range(c, kf, value_number(c, m.Get(k), kf), -1e30, 1e30);
    }
    if (std::abs(glm::determinant(glm::mat3(matrix))) < 1e-12f) c.fail(f + ".matrix", "is singular");
  }
  std::string why;
  const fs::path resolved = resolve_inside_root(access, c.dir / uri, why);
  if (resolved.empty()) c.fail(f + ".uri", "'" + uri + "' " + why);
  try {
    image::ExrLimits limits;
    limits.max_file_bytes = static_cast<long long>(c.options.max_file_bytes);
    return Environment(image::read_hdr_image(resolved, limits), strength, matrix);
  } catch (const image::ImageError& e) {
    c.fail(f + ".uri", e.what());
  }
}

}  // namespace

GltfLoadResult load_gltf(ecs::World& world, const fs::path& path, const GltfLoadOptions& options) {
  const std::string file = path.string();
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw GltfError(file + ": file not found");
  if (!fs::is_regular_file(status)) throw GltfError(file + ": not a regular file");

  FileAccess access;
  access.root = fs::weakly_canonical(fs::absolute(path).parent_path());
  access.max_bytes = options.max_file_bytes;
  std::vector<unsigned char> bytes;
  std::string why;
  if (!read_file_capped(path, options.max_file_bytes, bytes, why)) throw GltfError(file + ": " + why);

  const bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  std::string_view json;
  std::size_t bin_length = 0;
  if (glb) {
    try {
      const GlbChunks chunks = parse_glb(bytes);
      json = chunks.json;
      bin_length = chunks.bin_length;
    } catch (const std::exception& e) {
      throw GltfError(file + ": " + e.what());
    }
  } else {
    json = std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  }
  if (const int depth = json_depth(json); depth > options.max_json_depth)
    throw GltfError(file + ": JSON nesting depth " + std::to_string(depth) + " exceeds the limit of " +
                    std::to_string(options.max_json_depth));

  if (const std::string bad = check_references(json, access, bin_length); !bad.empty()) throw GltfError(file + ": " + bad);

  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(make_fs_callbacks(&access));
  ImageLimits image_limits{options.max_texture_dimension};
  loader.SetImageLoader(load_image_checked, &image_limits);
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    const std::string base_dir = access.root.string();
    ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()),
                                           base_dir)
             : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                          static_cast<unsigned int>(bytes.size()), base_dir);
  } catch (const std::exception& e) {
    throw GltfError(file + ": malformed glTF: " + e.what());
  }
  if (!ok) {
    std::string msg = err.empty() ? access.last_error : err;
    while (!msg.empty() && msg.back() == '\n') msg.pop_back();
    throw GltfError(file + ": " + (msg.empty() ? "malformed glTF" : msg));
  }

  GltfLoadResult result;
  const Context c{path.filename().string(), access.root, model, options, result};
  for (const std::string& ext : model.extensionsRequired)
    if (!kSupportedExtensions.contains(ext)) c.fail("extensionsRequired", "extension '" + ext + "' is not supported");

  SceneAssets sa;
  sa.generation = next_scene_generation();
  sa.source = path;
  sa.textures = load_textures(c);
  sa.materials = load_materials(c);
  {
    // Mips for footprint-filtered lookups, averaged in the space each
    // texture is read in (colour: linear light), a cut-out's base colour
    // weighted by its alpha.
    std::vector<std::uint8_t> colour(sa.textures.size(), 0), cut_out(sa.textures.size(), 0);
    for (const material::Material& m : sa.materials) {
      for (const auto t : {m.base_color_texture, m.emissive_texture})
        if (t >= 0) colour[static_cast<std::size_t>(t)] = 1;
      if (m.base_color_texture >= 0 && m.alpha_mode != material::AlphaMode::Opaque)
        cut_out[static_cast<std::size_t>(m.base_color_texture)] = 1;
    }
    for (std::size_t t = 0; t < sa.textures.size(); ++t) sa.textures[t].build_mips(colour[t] != 0, cut_out[t] != 0);
  }
  const auto default_material = static_cast<std::uint32_t>(sa.materials.size() - 1);
  const AccessorReader reader{model, c.file};
  std::vector<std::shared_ptr<const MeshAsset>> gltf_meshes;
  for (std::size_t m = 0; m < model.meshes.size(); ++m)
    gltf_meshes.push_back(std::make_shared<const MeshAsset>(load_mesh(c, reader, m, default_material)));
  sa.meshes = gltf_meshes;

  if (model.scenes.empty()) c.fail("scenes", "the file has no scene");
  const std::size_t scene_index = model.defaultScene >= 0 ? static_cast<std::size_t>(model.defaultScene) : 0;
  if (scene_index >= model.scenes.size()) c.fail("scene", "default scene " + std::to_string(scene_index) + " is out of range");
  if (options.load_environment) sa.environment = load_environment(c, access, scene_index);

  // Walk the default scene depth first; every node gets exactly one parent.
  std::vector<int> parent_of(model.nodes.size(), -2);  // -2 = not reached
  std::vector<std::pair<int, int>> stack;              // (node, parent)
  const auto& roots = model.scenes[scene_index].nodes;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, -1);
  std::map<std::pair<std::size_t, std::array<float, 3>>, std::uint32_t> baked;
  std::vector<ecs::Entity> entity_of(model.nodes.size());
  while (!stack.empty()) {
    const auto [node, parent] = stack.back();
    stack.pop_back();
    const std::string f = parent < 0 ? idx("scenes", scene_index) + ".nodes" : idx("nodes", static_cast<std::size_t>(parent)) + ".children";
    if (node < 0 || static_cast<std::size_t>(node) >= model.nodes.size())
      c.fail(f, "node " + std::to_string(node) + " is out of range (" + std::to_string(model.nodes.size()) + " nodes)");
    const auto ni = static_cast<std::size_t>(node);
    if (parent_of[ni] != -2) c.fail(idx("nodes", ni), "is reached twice (it has two parents or is part of a cycle)");
    parent_of[ni] = parent;
    const tinygltf::Node& n = model.nodes[ni];
    const std::string nf = idx("nodes", ni);

    const NodeTransform nt = node_transform(c, ni);
    if (nt.needs_bake && !n.children.empty())
      c.fail(nf, "non-uniform or negative scale on a node with children is not supported");
    const ecs::Entity e = world.spawn();
    entity_of[ni] = e;
    result.entities.push_back(e);
    world.emplace<transform::Transform>(e, nt.local);
    if (parent >= 0) world.emplace<transform::Parent>(e, transform::Parent{entity_of[static_cast<std::size_t>(parent)]});
    world.emplace<Name>(e, Name{n.name.empty() ? nf : n.name});
    world.emplace<GltfNodeSource>(e, GltfNodeSource{static_cast<std::uint32_t>(ni), nt.local, nt.needs_bake});
    if (n.extras.IsObject()) {
      NodeMarkers markers;
      for (const std::string& key : n.extras.Keys()) {
        const tinygltf::Value& v = n.extras.Get(key);
        const bool set = (v.IsBool() && v.Get<bool>()) || (v.IsNumber() && v.GetNumberAsDouble() != 0.0) || v.IsObject();
        if (set) markers.keys.push_back(key);
      }
      markers.scale = nt.local.scale * nt.residual_scale;
      if (!markers.keys.empty()) world.emplace<NodeMarkers>(e, std::move(markers));
    }

    if (n.mesh >= 0) {
      if (static_cast<std::size_t>(n.mesh) >= model.meshes.size())
        c.fail(nf + ".mesh", "mesh " + std::to_string(n.mesh) + " is out of range (" + std::to_string(model.meshes.size()) + " meshes)");
      auto mesh_index = static_cast<std::uint32_t>(n.mesh);
      if (nt.needs_bake) {
        const auto key = std::make_pair(static_cast<std::size_t>(n.mesh),
                                        std::array<float, 3>{nt.residual_scale.x, nt.residual_scale.y, nt.residual_scale.z});
        if (auto it = baked.find(key); it != baked.end()) {
          mesh_index = it->second;
        } else {
          sa.meshes.push_back(std::make_shared<const MeshAsset>(bake_scale(*gltf_meshes[static_cast<std::size_t>(n.mesh)], nt.residual_scale)));
          mesh_index = baked[key] = static_cast<std::uint32_t>(sa.meshes.size() - 1);
        }
      }
      world.emplace<MeshInstance>(e, MeshInstance{mesh_index});
    }
    if (n.camera >= 0) {
      if (static_cast<std::size_t>(n.camera) >= model.cameras.size())
        c.fail(nf + ".camera", "camera " + std::to_string(n.camera) + " is out of range");
      const tinygltf::Camera& cam = model.cameras[static_cast<std::size_t>(n.camera)];
      const std::string cf = idx("cameras", static_cast<std::size_t>(n.camera));
      if (cam.type == "perspective") {
        Camera out;
        out.yfov_radians = finite_in_range(c, cf + ".perspective.yfov", cam.perspective.yfov, 1e-4, 3.14);
        out.aspect_ratio = finite_in_range(c, cf + ".perspective.aspectRatio", cam.perspective.aspectRatio, 0, 1e4);
        out.znear = finite_in_range(c, cf + ".perspective.znear", cam.perspective.znear, 0, 1e30);
        out.zfar = finite_in_range(c, cf + ".perspective.zfar", cam.perspective.zfar, 0, 1e30);
        world.emplace<Camera>(e, out);
      } else {
        c.warn(cf + ".type", "'" + cam.type + "' cameras are not supported; ignored");
      }
    }
    if (auto it = n.extensions.find("KHR_lights_punctual"); it != n.extensions.end()) {
      const std::string lf = nf + ".extensions.KHR_lights_punctual.light";
      if (!it->second.Has("light")) c.fail(lf, "is missing");
      const double li = value_number(c, it->second.Get("light"), lf);
      if (li < 0 || li >= static_cast<double>(model.lights.size()) || li != std::floor(li))
        c.fail(lf, "light " + std::to_string(li) + " is out of range (" + std::to_string(model.lights.size()) + " lights)");
      const tinygltf::Light& l = model.lights[static_cast<std::size_t>(li)];
      const std::string lif = "extensions.KHR_lights_punctual.lights[" + std::to_string(static_cast<int>(li)) + "]";
      PunctualLight pl;
      if (l.type == "point") pl.type = PunctualLight::Type::Point;
      else if (l.type == "spot") pl.type = PunctualLight::Type::Spot;
      else if (l.type == "directional") pl.type = PunctualLight::Type::Directional;
      else c.fail(lif + ".type", "must be point, spot or directional, got '" + l.type + "'");
      if (!l.color.empty()) pl.color = vec_in_range<3>(c, lif + ".color", l.color, 0, 1e30);
      pl.intensity = finite_in_range(c, lif + ".intensity", l.intensity, 0, 1e30);
      pl.range = finite_in_range(c, lif + ".range", l.range, 0, 1e30);
      if (pl.type == PunctualLight::Type::Spot) {
        pl.inner_cone_angle = finite_in_range(c, lif + ".spot.innerConeAngle", l.spot.innerConeAngle, 0, 1.5708);
        pl.outer_cone_angle = finite_in_range(c, lif + ".spot.outerConeAngle", l.spot.outerConeAngle, 0, 1.5708);
        if (pl.outer_cone_angle < pl.inner_cone_angle)
          c.fail(lif + ".spot.outerConeAngle", "is smaller than innerConeAngle");
      }
      if (l.extras.IsObject() && l.extras.Has("angular_radius")) {
        const std::string af = lif + ".extras.angular_radius";
        if (pl.type != PunctualLight::Type::Directional) c.fail(af, "is for directional lights only");
        const double r = value_number(c, l.extras.Get("angular_radius"), af);
        if (!(r >= 0 && r <= 0.5)) c.fail(af, "must lie in [0, 0.5] radians, got " + std::to_string(r));
        pl.angular_radius = static_cast<float>(r);
      }
      world.emplace<PunctualLight>(e, pl);
    }
    for (auto ch = n.children.rbegin(); ch != n.children.rend(); ++ch) stack.emplace_back(*ch, node);
  }

  for (const auto& m : sa.meshes) result.triangle_count += m->triangle_count();
  result.mesh_count = sa.meshes.size();
  world.insert_resource<SceneAssets>(std::move(sa));
  return result;
}

}  // namespace engine::scene
