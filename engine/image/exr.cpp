#include "engine/image/exr.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfVersion.h>
#include <stb/stb_image.h>

#include <Imath/half.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <mutex>
#include <span>
#include <string>

#include "engine/io/atomic_file.h"

namespace engine::image {

namespace {

namespace fs = std::filesystem;

std::string quote(const fs::path& p) { return p.string(); }

// Regular file, not too large; returns its size.
std::uintmax_t check_regular_file(const fs::path& path, long long max_bytes) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw ImageError(quote(path) + ": file not found");
  if (!fs::is_regular_file(status)) throw ImageError(quote(path) + ": not a regular file");
  const auto size = fs::file_size(path, ec);
  if (ec) throw ImageError(quote(path) + ": cannot read file size: " + ec.message());
  if (static_cast<long long>(size) > max_bytes)
    throw ImageError(quote(path) + ": file is " + std::to_string(size) + " bytes, over the limit of " +
                     std::to_string(max_bytes));
  return size;
}

std::array<unsigned char, 16> read_head(const fs::path& path) {
  std::array<unsigned char, 16> head{};
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ImageError(quote(path) + ": cannot open for reading");
  f.read(reinterpret_cast<char*>(head.data()), head.size());
  return head;
}

bool is_exr_magic(const std::array<unsigned char, 16>& h) {
  return h[0] == 0x76 && h[1] == 0x2f && h[2] == 0x31 && h[3] == 0x01;
}

// Walks the single-part header's attributes (name, type, int32 size, value)
// and refuses one whose size is negative or runs past the end of the file,
// naming it. OpenEXR allocates an attribute's declared size before reading
// it: the EXR fuzzer's 24-byte file declared 1,768,685,568 bytes for one and
// made the reader take 250 MB and half a second (docs/reliability.md).
void check_header_attributes(const fs::path& path, std::uintmax_t file_size) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ImageError(quote(path) + ": cannot open for reading");
  f.seekg(8);  // magic and version
  std::uintmax_t pos = 8;
  // Names are shown with bytes outside printable ASCII as \\xNN (a hostile
  // file's name goes into the message).
  const auto shown = [](const std::string& raw) {
    std::string out;
    for (const unsigned char c : raw) {
      if (c >= 0x20 && c < 0x7f) {
        out.push_back(static_cast<char>(c));
      } else {
        static const char* hex = "0123456789abcdef";
        out += "\\x";
        out.push_back(hex[c >> 4]);
        out.push_back(hex[c & 15]);
      }
    }
    return out;
  };
  const auto read_name = [&](const char* what) {
    std::string s;
    for (char c = 0; f.get(c) && c != 0;) {
      s.push_back(c);
      if (s.size() > 255) throw ImageError(quote(path) + ": header: " + what + " longer than 255 bytes at byte " + std::to_string(pos));
    }
    if (!f) throw ImageError(quote(path) + ": header: the file ends inside an attribute's " + what + " (byte " + std::to_string(pos) + ")");
    pos += s.size() + 1;
    return s;
  };
  for (int count = 0;; ++count) {
    const std::string name = read_name("name");
    if (name.empty()) return;  // the header's terminating null byte
    if (count >= 100000) throw ImageError(quote(path) + ": header: more than 100,000 attributes");
    const std::string type = read_name("type name");
    std::array<unsigned char, 4> b{};
    if (!f.read(reinterpret_cast<char*>(b.data()), 4))
      throw ImageError(quote(path) + ": header: attribute '" + shown(name) + "' (" + shown(type) + "): the file ends before its size");
    pos += 4;
    const std::int32_t size = static_cast<std::int32_t>(b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<std::uint32_t>(b[3]) << 24));
    if (size < 0 || static_cast<std::uintmax_t>(size) > file_size - pos)
      throw ImageError(quote(path) + ": header: attribute '" + shown(name) + "' (" + shown(type) + ") declares " + std::to_string(size) +
                       " bytes, but the file has " + std::to_string(file_size - pos) + " left");
    pos += static_cast<std::uintmax_t>(size);
    f.seekg(static_cast<std::streamoff>(pos));
  }
}

void check_dimensions(const fs::path& path, long long w, long long h, const ExrLimits& limits) {
  if (w <= 0 || h <= 0) throw ImageError(quote(path) + ": dataWindow is empty (" + std::to_string(w) + "x" +
                                         std::to_string(h) + ")");
  if (w > limits.max_dimension || h > limits.max_dimension || w * h > limits.max_pixels)
    throw ImageError(quote(path) + ": dataWindow " + std::to_string(w) + "x" + std::to_string(h) +
                     " exceeds the size limit (" + std::to_string(limits.max_dimension) + " per side, " +
                     std::to_string(limits.max_pixels) + " pixels)");
}

void check_finite(const fs::path& path, const ImageRGB& img, const char* verb) {
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const glm::vec3& p = img.at(x, y);
      if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b))
        throw ImageError(quote(path) + ": " + verb + " non-finite value at pixel (" + std::to_string(x) + ", " +
                         std::to_string(y) + ")");
    }
}

}  // namespace

ImageRGB read_exr(const fs::path& path, const ExrLimits& limits) {
  const auto size = check_regular_file(path, limits.max_file_bytes);
  if (size < 8) throw ImageError(quote(path) + ": too short to be an OpenEXR file");
  const auto head = read_head(path);
  if (!is_exr_magic(head)) throw ImageError(quote(path) + ": not an OpenEXR file (bad magic number)");
  int version = 0;
  std::memcpy(&version, head.data() + 4, sizeof(int));
  if (Imf::getVersion(version) != 2) throw ImageError(quote(path) + ": unsupported OpenEXR version " +
                                                      std::to_string(Imf::getVersion(version)));
  if (Imf::isMultiPart(version)) throw ImageError(quote(path) + ": multi-part OpenEXR files are not supported");
  if (Imf::isNonImage(version)) throw ImageError(quote(path) + ": deep OpenEXR files are not supported");
  if (Imf::isTiled(version)) throw ImageError(quote(path) + ": tiled OpenEXR files are not supported (scanline only)");
  check_header_attributes(path, size);
  // OpenEXR sizes its line buffers from the data window while opening the
  // file, before check_dimensions can look: the EXR fuzzer's 104-byte file
  // with a 67,108,353-pixel-wide window made it ask for 2.17 GB. Its own
  // sanity check refuses wider windows first; set once, process-wide, to the
  // largest size any caller accepts (ExrLimits' default).
  static std::once_flag exr_size_cap;
  std::call_once(exr_size_cap, [] { Imf::Header::setMaxImageSize(ExrLimits{}.max_dimension, ExrLimits{}.max_dimension); });

  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    if (header.hasType() && header.type() != Imf::SCANLINEIMAGE)
      throw ImageError(quote(path) + ": part type '" + header.type() + "' is not supported (scanline only)");
    const Imath::Box2i dw = header.dataWindow();
    const long long w = static_cast<long long>(dw.max.x) - dw.min.x + 1;
    const long long h = static_cast<long long>(dw.max.y) - dw.min.y + 1;
    check_dimensions(path, w, h, limits);

    const Imf::ChannelList& channels = header.channels();
    const bool has_rgb = channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
    const bool has_y = channels.findChannel("Y") != nullptr;
    if (!has_rgb && !has_y)
      throw ImageError(quote(path) + ": channels: needs R, G and B (or Y); found none of them");

    ImageRGB img(static_cast<int>(w), static_cast<int>(h));
    auto* base = reinterpret_cast<char*>(img.pixels.data()) -
                 (static_cast<std::ptrdiff_t>(dw.min.x) + static_cast<std::ptrdiff_t>(dw.min.y) * w) *
                     static_cast<std::ptrdiff_t>(sizeof(glm::vec3));
    const std::size_t xs = sizeof(glm::vec3), ys = sizeof(glm::vec3) * static_cast<std::size_t>(w);
    Imf::FrameBuffer fb;
    if (has_rgb) {
      fb.insert("R", Imf::Slice(Imf::FLOAT, base + 0 * sizeof(float), xs, ys));
      fb.insert("G", Imf::Slice(Imf::FLOAT, base + 1 * sizeof(float), xs, ys));
      fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    } else {
      fb.insert("Y", Imf::Slice(Imf::FLOAT, base, xs, ys));
    }
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    if (!has_rgb)
      for (auto& p : img.pixels) p = glm::vec3(p.r);
    check_finite(path, img, "contains a");
    return img;
  } catch (const ImageError&) {
    throw;
  } catch (const std::exception& e) {
    throw ImageError(quote(path) + ": malformed OpenEXR file: " + e.what());
  }
}

void write_exr(const fs::path& path, const ImageRGB& image, ExrPixelType type) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
    throw ImageError(quote(path) + ": refusing to write an empty or inconsistent image");
  check_finite(path, image, "refusing to write a");

  // Half output: clamp into the half range, then convert ourselves (OpenEXR
  // does not convert between a slice's type and the channel's type on write).
  const bool half = type == ExrPixelType::Half;
  std::vector<Imath::half> halves;
  if (half) {
    constexpr float kHalfMax = 65504.0f;
    halves.resize(image.pixels.size() * 3);
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c)
        halves[i * 3 + static_cast<std::size_t>(c)] = Imath::half(std::clamp(image.pixels[i][c], -kHalfMax, kHalfMax));
  }
  const Imf::PixelType channel_type = half ? Imf::HALF : Imf::FLOAT;
  std::string bytes;
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(channel_type));
    Imf::StdOSStream stream;
    {
      Imf::OutputFile out(stream, header);
      auto* base = half ? reinterpret_cast<char*>(halves.data())
                        : const_cast<char*>(reinterpret_cast<const char*>(image.pixels.data()));
      const std::size_t comp = half ? sizeof(Imath::half) : sizeof(float);
      const std::size_t xs = 3 * comp, ys = xs * static_cast<std::size_t>(image.width);
      Imf::FrameBuffer fb;
      fb.insert("R", Imf::Slice(channel_type, base + 0 * comp, xs, ys));
      fb.insert("G", Imf::Slice(channel_type, base + 1 * comp, xs, ys));
      fb.insert("B", Imf::Slice(channel_type, base + 2 * comp, xs, ys));
      out.setFrameBuffer(fb);
      out.writePixels(image.height);
    }
    bytes = stream.str();
  } catch (const std::exception& e) {
    throw ImageError(quote(path) + ": OpenEXR encoding failed: " + e.what());
  }
  try {
    io::write_file_atomically(path, std::as_bytes(std::span(bytes.data(), bytes.size())));
  } catch (const io::IoError& e) {
    throw ImageError(e.what());
  }
}

ImageRGB read_hdr(const fs::path& path, const ExrLimits& limits) {
  check_regular_file(path, limits.max_file_bytes);
  const auto head = read_head(path);
  if (std::memcmp(head.data(), "#?RADIANCE", 10) != 0 && std::memcmp(head.data(), "#?RGBE", 6) != 0)
    throw ImageError(quote(path) + ": not a Radiance HDR file (missing #?RADIANCE signature)");
  std::ifstream f(path, std::ios::binary);
  const std::vector<unsigned char> data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(data.data(), static_cast<int>(data.size()), &w, &h, &comp))
    throw ImageError(quote(path) + ": malformed Radiance HDR header: " + stbi_failure_reason());
  check_dimensions(path, w, h, limits);
  float* pixels = stbi_loadf_from_memory(data.data(), static_cast<int>(data.size()), &w, &h, &comp, 3);
  if (!pixels) throw ImageError(quote(path) + ": malformed Radiance HDR data: " + stbi_failure_reason());
  ImageRGB img(w, h);
  std::memcpy(img.pixels.data(), pixels, img.pixels.size() * sizeof(glm::vec3));
  stbi_image_free(pixels);
  check_finite(path, img, "contains a");
  return img;
}

ImageRGB read_hdr_image(const fs::path& path, const ExrLimits& limits) {
  check_regular_file(path, limits.max_file_bytes);
  const auto head = read_head(path);
  if (is_exr_magic(head)) return read_exr(path, limits);
  if (std::memcmp(head.data(), "#?", 2) == 0) return read_hdr(path, limits);
  throw ImageError(quote(path) + ": not an OpenEXR or Radiance HDR image (unrecognised magic bytes)");
}

}  // namespace engine::image
