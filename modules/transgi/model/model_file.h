#pragma once
// The .tgm model file.
//
//   header (24 bytes): magic "TGM\0", u32 format version, u64 payload bytes,
//                      u64 FNV-1a 64 checksum of the payload
//   payload: decoder layout and weights, latent dimension, per mesh its name,
//            content hash, vertex-to-latent map and latents, then the bake
//            settings and metrics as JSON text. Little-endian throughout.
//
// Writing goes to a temporary file, fsync, then rename. Reading rejects a
// truncated, corrupt or newer-version file, and validate_model() rejects a
// model whose meshes no longer match the scene, each with a message that
// says what to do.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>
#include <stdexcept>

#include "model/transfer_model.h"

namespace transgi::model {

// 2: a flags word after the metrics (bit 0: TransferModel::demodulated).
inline constexpr std::uint32_t kModelFormatVersion = 2;

class ModelFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void save_model(const std::filesystem::path& path, const TransferModel& model);
TransferModel load_model(const std::filesystem::path& path);
// The same file's bytes, for containers that hold a model (a bake's
// checkpoint); `name` is what errors call the bytes.
std::vector<std::byte> encode_model(const TransferModel& model);
TransferModel decode_model(std::span<const std::byte> bytes, const std::string& name);

// Throws ModelFileError if the model does not belong to these assets (mesh
// count, names or content hashes differ), naming the first stale mesh.
// allow_unbaked: the scene may have meshes after the model's last one (a
// ground plane or props added since the bake); those get no latents and are
// shaded diffusely from the probes. The meshes the model has must still match.
// Returns how many of the scene's meshes have no latents.
std::size_t validate_model(const TransferModel& model, const engine::scene::SceneAssets& assets,
                           const std::filesystem::path& model_path, bool allow_unbaked = false);

}  // namespace transgi::model
