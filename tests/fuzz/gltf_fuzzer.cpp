// glTF import (.gltf and .glb) of untrusted bytes: the importer must throw
// GltfError (or another std::exception naming the problem), never crash, leak
// or hit undefined behaviour. Inputs starting with the GLB magic are loaded as
// .glb, the rest as .gltf; external URIs point into an empty folder, so buffers
// and images reach the decoders through data: URIs and GLB chunks.
#include <cstring>
#include <exception>

#include "engine/ecs/world.h"
#include "engine/scene/gltf_loader.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const auto path = transgi_fuzz::write_input(glb ? "scene.glb" : "scene.gltf", data, size);
  engine::ecs::World world;
  engine::scene::GltfLoadOptions options;
  options.max_file_bytes = 4u << 20;     // keeps one input's work bounded
  options.max_texture_dimension = 1024;  // and its memory
  try {
    engine::scene::load_gltf(world, path, options);
  } catch (const std::exception&) {
    // A clear error is the expected outcome for most inputs.
  }
  return 0;
}
