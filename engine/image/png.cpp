#include "engine/image/png.h"

#include <cstddef>
#include <span>
#include <stb/stb_image_write.h>

#include "engine/io/atomic_file.h"

namespace engine::image {

void write_png(const std::filesystem::path& path, const Rgb8Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 3)
    throw io::IoError(path.string() + ": invalid image size " + std::to_string(image.width) + "x" +
                      std::to_string(image.height));
  std::vector<std::byte> encoded;
  auto sink = [](void* ctx, void* data, int size) {
    auto* out = static_cast<std::vector<std::byte>*>(ctx);
    const auto* p = static_cast<const std::byte*>(data);
    out->insert(out->end(), p, p + size);
  };
  if (!stbi_write_png_to_func(sink, &encoded, image.width, image.height, 3, image.pixels.data(), image.width * 3))
    throw io::IoError(path.string() + ": PNG encoding failed");
  io::write_file_atomically(path, encoded);
}

}  // namespace engine::image
