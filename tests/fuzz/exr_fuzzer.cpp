// EXR and Radiance HDR reading of untrusted bytes (environment maps, images
// given to `transgi compare`): a std::exception naming the file, never a
// crash. The limits keep one input's allocation small.
#include <exception>

#include "engine/image/exr.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  engine::image::ExrLimits limits;
  limits.max_dimension = 4096;
  limits.max_pixels = 1 << 22;
  limits.max_file_bytes = 8 << 20;
  // read_hdr_image picks the reader by magic bytes, so one corpus covers both.
  const auto path = transgi_fuzz::write_input("image.exr", data, size);
  try {
    (void)engine::image::read_hdr_image(path, limits);
  } catch (const std::exception&) {
  }
  return 0;
}
