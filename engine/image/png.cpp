#include "engine/image/png.h"

#include <algorithm>
#include <cstddef>
#include <span>
#include <stb/stb_image.h>
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

Rgb8Image read_png(const std::filesystem::path& path) {
  int w = 0, h = 0, channels = 0;
  unsigned char* data = stbi_load(path.string().c_str(), &w, &h, &channels, 3);
  if (!data) throw io::IoError(path.string() + ": cannot read PNG: " + (stbi_failure_reason() ? stbi_failure_reason() : "unknown"));
  Rgb8Image img(w, h);
  std::copy(data, data + img.pixels.size(), img.pixels.begin());
  stbi_image_free(data);
  return img;
}

}  // namespace engine::image
