// PNG and JPEG decoding as the glTF importer does it for textures (magic
// bytes, dimension caps, RGBA8 out), on untrusted bytes: false with a reason,
// never a crash.
#include <string>

#include <tiny_gltf.h>

#include "engine/scene/gltf_guard.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > (1u << 22)) return 0;
  tinygltf::Image image;
  std::string err, warn;
  engine::scene::gltf_detail::ImageLimits limits;
  limits.max_dimension = 2048;
  engine::scene::gltf_detail::load_image_checked(&image, 0, &err, &warn, 0, 0, data, static_cast<int>(size), &limits);
  return 0;
}
