#include "model/model_file.h"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <span>

#include <nlohmann/json.hpp>

#include "engine/io/atomic_file.h"
#include "engine/core/fnv1a.h"

namespace transgi::model {

namespace {

constexpr char kMagic[4] = {'T', 'G', 'M', '\0'};
constexpr std::size_t kHeaderBytes = 24;
constexpr std::uint64_t kMaxPayload = 4ull << 30;

std::uint64_t fnv1a(const std::byte* p, std::size_t n) {
  engine::core::Fnv1a f;
  f.bytes(p, n);
  return f.h;
}

struct Writer {
  std::vector<std::byte> out;
  template <class T>
  void value(const T& v) {
    const auto* p = reinterpret_cast<const std::byte*>(&v);
    out.insert(out.end(), p, p + sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    value<std::uint64_t>(v.size());
    const auto* p = reinterpret_cast<const std::byte*>(v.data());
    out.insert(out.end(), p, p + v.size() * sizeof(T));
  }
  void string(const std::string& s) {
    value<std::uint64_t>(s.size());
    const auto* p = reinterpret_cast<const std::byte*>(s.data());
    out.insert(out.end(), p, p + s.size());
  }
};

// Bounds-checked reads: a corrupt length can never make us read past the
// payload or allocate more than it could hold.
struct Reader {
  std::span<const std::byte> in;
  std::size_t at = 0;
  std::string file;

  [[noreturn]] void fail(const std::string& what) const {
    throw ModelFileError(file + ": corrupt model file (" + what + " at byte " + std::to_string(kHeaderBytes + at) +
                         "); re-run transgi bake to rebuild it");
  }
  template <class T>
  T value(const char* what) {
    if (in.size() - at < sizeof(T)) fail(std::string("truncated ") + what);
    T v;
    std::memcpy(&v, in.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  template <class T>
  std::vector<T> array(const char* what, std::uint64_t expected = UINT64_MAX) {
    const auto n = value<std::uint64_t>(what);
    if (expected != UINT64_MAX && n != expected)
      fail(std::string(what) + " count " + std::to_string(n) + " differs from the expected " + std::to_string(expected));
    if (n > (in.size() - at) / sizeof(T)) fail(std::string(what) + " length runs past the end");
    std::vector<T> v(n);
    std::memcpy(v.data(), in.data() + at, n * sizeof(T));
    at += n * sizeof(T);
    return v;
  }
  std::string string(const char* what) {
    const auto n = value<std::uint64_t>(what);
    if (n > in.size() - at) fail(std::string(what) + " length runs past the end");
    std::string s(reinterpret_cast<const char*>(in.data() + at), n);
    at += n;
    return s;
  }
};

// The bake's visibility fraction, from its free-form settings: models from
// before it was recorded, or from tools that write other settings, were
// baked with the default.
float visibility_fraction_of(const std::string& bake_settings, const Reader& r) {
  const nlohmann::json j = nlohmann::json::parse(bake_settings, nullptr, false);
  if (!j.is_object() || !j.contains("visibility_fraction")) return kDefaultVisibilityFraction;
  const nlohmann::json& v = j["visibility_fraction"];
  if (!v.is_number() || !(v.get<double>() >= 0.0) || !(v.get<double>() <= 1e6))
    r.fail("bake settings' visibility_fraction " + v.dump() + " is not a number in [0, 1e6]");
  return v.get<float>();
}

}  // namespace

std::vector<std::byte> encode_model(const TransferModel& model) {
  Writer w;
  const MlpLayout& l = model.decoder.layout();
  w.value<std::int32_t>(l.inputs);
  w.value<std::int32_t>(l.width);
  w.value<std::int32_t>(l.hidden_layers);
  w.value<std::int32_t>(l.outputs);
  w.value<std::int32_t>(model.latent_dim);
  w.array(model.decoder.params());
  w.value<std::uint64_t>(model.meshes.size());
  for (const MeshLatents& m : model.meshes) {
    w.string(m.name);
    w.value(m.content_hash);
    w.array(m.latents.vertex_to_latent);
    w.array(m.latents.values);
  }
  w.string(model.bake_settings_json);
  w.string(model.metrics_json);
  w.value<std::uint32_t>(model.demodulated ? 1u : 0u);

  // The header goes in front of the payload, in place.
  const std::uint32_t version = kModelFormatVersion;
  const std::uint64_t size = w.out.size(), checksum = fnv1a(w.out.data(), w.out.size());
  std::array<std::byte, kHeaderBytes> header{};
  std::memcpy(header.data(), kMagic, 4);
  std::memcpy(header.data() + 4, &version, 4);
  std::memcpy(header.data() + 8, &size, 8);
  std::memcpy(header.data() + 16, &checksum, 8);
  w.out.insert(w.out.begin(), header.begin(), header.end());
  return std::move(w.out);
}

void save_model(const std::filesystem::path& path, const TransferModel& model) {
  engine::io::write_file_atomically(path, encode_model(model));
}

TransferModel load_model(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw ModelFileError(name + ": model file not found; run transgi bake first");
  const auto file_size = std::filesystem::file_size(path, ec);
  if (ec || file_size < kHeaderBytes)
    throw ModelFileError(name + ": truncated model file (" + std::to_string(file_size) + " bytes); re-run transgi bake");
  if (file_size > kMaxPayload + kHeaderBytes) throw ModelFileError(name + ": file is too large to be a model");
  std::vector<std::byte> bytes(file_size);
  std::ifstream f(path, std::ios::binary);
  f.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(file_size));
  if (static_cast<std::uint64_t>(f.gcount()) != file_size) throw ModelFileError(name + ": cannot read the file");
  return decode_model(bytes, name);
}

TransferModel decode_model(std::span<const std::byte> bytes, const std::string& name) {
  const std::uint64_t file_size = bytes.size();
  if (file_size < kHeaderBytes)
    throw ModelFileError(name + ": truncated model file (" + std::to_string(file_size) + " bytes); re-run transgi bake");
  if (std::memcmp(bytes.data(), kMagic, 4) != 0) throw ModelFileError(name + ": not a TransGI model file (bad magic)");
  std::uint32_t version;
  std::uint64_t payload, checksum;
  std::memcpy(&version, bytes.data() + 4, 4);
  std::memcpy(&payload, bytes.data() + 8, 8);
  std::memcpy(&checksum, bytes.data() + 16, 8);
  if (version > kModelFormatVersion)
    throw ModelFileError(name + ": written by a newer TransGI (model format " + std::to_string(version) +
                         "); this build reads format " + std::to_string(kModelFormatVersion) +
                         ". Update TransGI or re-bake with this version");
  if (version < 1) throw ModelFileError(name + ": unknown model format version " + std::to_string(version));
  if (payload != file_size - kHeaderBytes)
    throw ModelFileError(name + ": truncated or padded model file (header says " + std::to_string(payload) +
                         " payload bytes, file has " + std::to_string(file_size - kHeaderBytes) + "); re-run transgi bake");
  if (fnv1a(bytes.data() + kHeaderBytes, payload) != checksum)
    throw ModelFileError(name + ": checksum mismatch, the model file is corrupt; re-run transgi bake");

  Reader r{bytes.subspan(kHeaderBytes), 0, name};
  MlpLayout layout;
  layout.inputs = r.value<std::int32_t>("layout");
  layout.width = r.value<std::int32_t>("layout");
  layout.hidden_layers = r.value<std::int32_t>("layout");
  layout.outputs = r.value<std::int32_t>("layout");
  TransferModel model;
  model.latent_dim = r.value<std::int32_t>("latent dimension");
  if (layout.inputs < 1 || layout.inputs > 4096 || layout.width < 1 || layout.width > 4096 || layout.hidden_layers < 0 ||
      layout.hidden_layers > 64 || layout.outputs < 1 || layout.outputs > 4096 || model.latent_dim < 0 ||
      model.latent_dim + 9 != layout.inputs)
    r.fail("implausible decoder layout");
  model.decoder = Mlp(layout);
  model.decoder.params() = r.array<float>("decoder weights", layout.parameter_count());
  for (float v : model.decoder.params())
    if (!std::isfinite(v)) r.fail("non-finite decoder weight");
  const auto meshes = r.value<std::uint64_t>("mesh count");
  if (meshes > 1'000'000) r.fail("implausible mesh count");
  for (std::uint64_t i = 0; i < meshes; ++i) {
    MeshLatents m;
    m.name = r.string("mesh name");
    m.content_hash = r.value<std::uint64_t>("content hash");
    m.latents.dimension = model.latent_dim;
    m.latents.vertex_to_latent = r.array<std::uint32_t>("vertex map");
    m.latents.values = r.array<float>("latents");
    if (model.latent_dim > 0 && m.latents.values.size() % static_cast<std::size_t>(model.latent_dim) != 0) r.fail("latent table size");
    for (std::uint32_t row : m.latents.vertex_to_latent)
      if (row >= m.latents.rows()) r.fail("vertex map points past the latent table");
    for (float v : m.latents.values)
      if (!std::isfinite(v)) r.fail("non-finite latent");
    model.meshes.push_back(std::move(m));
  }
  model.bake_settings_json = r.string("bake settings");
  model.visibility_fraction = visibility_fraction_of(model.bake_settings_json, r);
  model.metrics_json = r.string("metrics");
  if (version >= 2) {
    const auto flags = r.value<std::uint32_t>("flags");
    if (flags & ~1u) r.fail("unknown flags " + std::to_string(flags));
    model.demodulated = (flags & 1u) != 0;
  }
  if (r.at != r.in.size()) r.fail("trailing bytes");
  return model;
}

std::size_t validate_model(const TransferModel& model, const engine::scene::SceneAssets& assets,
                           const std::filesystem::path& model_path, bool allow_unbaked) {
  const std::string hint = "; re-bake it with: transgi bake --scene " + assets.source.string() + " --out " + model_path.string();
  const bool extra_allowed = allow_unbaked && model.meshes.size() < assets.meshes.size();
  if (model.meshes.size() != assets.meshes.size() && !extra_allowed)
    throw ModelFileError(model_path.string() + ": stale model: it has " + std::to_string(model.meshes.size()) +
                         " meshes, the scene has " + std::to_string(assets.meshes.size()) + hint +
                         (model.meshes.size() < assets.meshes.size() ? " (or pass --allow-unbaked to shade the scene's last " +
                                                                          std::to_string(assets.meshes.size() - model.meshes.size()) +
                                                                          " meshes diffusely)"
                                                                    : ""));
  for (std::uint32_t i = 0; i < model.meshes.size(); ++i) {
    const MeshLatents& m = model.meshes[i];
    if (m.content_hash != mesh_content_hash(assets, i) || m.latents.vertex_to_latent.size() != assets.meshes[i]->vertex_count())
      throw ModelFileError(model_path.string() + ": stale model: mesh " + std::to_string(i) + " '" + assets.meshes[i]->name +
                           "' changed since the bake (content hash differs)" + hint);
  }
  return assets.meshes.size() - model.meshes.size();
}

}  // namespace transgi::model
