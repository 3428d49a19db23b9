#include "engine/scene/gltf_guard.h"

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <cctype>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <stb/stb_image.h>

namespace engine::scene::gltf_detail {

namespace fs = std::filesystem;

int json_depth(std::string_view text) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '{' || c == '[') deepest = std::max(deepest, ++depth);
    else if (c == '}' || c == ']') --depth;
  }
  return deepest;
}

namespace {
std::uint32_t read_u32(const std::vector<unsigned char>& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;  // GLB is little-endian, as is every platform we build for
}
}  // namespace

GlbChunks parse_glb(const std::vector<unsigned char>& b) {
  if (b.size() < 20) throw std::runtime_error("GLB header: file is only " + std::to_string(b.size()) + " bytes");
  if (std::memcmp(b.data(), "glTF", 4) != 0) throw std::runtime_error("GLB header: magic is not 'glTF'");
  if (read_u32(b, 4) != 2) throw std::runtime_error("GLB header: version " + std::to_string(read_u32(b, 4)) + " is not 2");
  const std::uint32_t length = read_u32(b, 8);
  if (length > b.size()) throw std::runtime_error("GLB header: length " + std::to_string(length) + " exceeds file size " +
                                                  std::to_string(b.size()));
  GlbChunks out;
  std::size_t at = 12;
  int chunk = 0;
  while (at + 8 <= length) {
    const std::uint32_t clen = read_u32(b, at), ctype = read_u32(b, at + 4);
    if (clen > length - at - 8)
      throw std::runtime_error("GLB chunk " + std::to_string(chunk) + ": chunkLength " + std::to_string(clen) +
                               " runs past the end of the file");
    if (chunk == 0) {
      if (ctype != 0x4E4F534Au) throw std::runtime_error("GLB chunk 0: first chunk must be JSON");
      out.json = std::string_view(reinterpret_cast<const char*>(b.data() + at + 8), clen);
    } else if (chunk == 1 && ctype == 0x004E4942u) {
      out.bin_offset = at + 8;
      out.bin_length = clen;
    }
    at += 8 + clen;
    ++chunk;
  }
  if (chunk == 0) throw std::runtime_error("GLB: no JSON chunk");
  return out;
}

fs::path resolve_inside_root(const FileAccess& access, const fs::path& path, std::string& why) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(path, ec);
  if (ec) {
    why = "cannot resolve path: " + ec.message();
    return {};
  }
  // Component-wise prefix test: "/a/bc" is not inside "/a/b".
  auto r = access.root.begin(), c = canonical.begin();
  for (; r != access.root.end(); ++r, ++c)
    if (c == canonical.end() || *r != *c) {
      why = "points outside the scene's folder " + access.root.string();
      return {};
    }
  const auto status = fs::status(canonical, ec);
  if (ec || !fs::exists(status)) {
    why = "file not found";
    return {};
  }
  if (fs::is_directory(status)) {
    why = "is a directory, not a file";
    return {};
  }
  if (!fs::is_regular_file(status)) {
    why = "is not a regular file";
    return {};
  }
  return canonical;
}

bool read_file_capped(const fs::path& path, std::uint64_t max_bytes, std::vector<unsigned char>& out, std::string& why) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) {
    why = "cannot read file size: " + ec.message();
    return false;
  }
  if (size > max_bytes) {
    why = "file is " + std::to_string(size) + " bytes, over the limit of " + std::to_string(max_bytes);
    return false;
  }
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    why = "cannot open for reading";
    return false;
  }
  out.resize(size);
  f.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(size));
  if (static_cast<std::uint64_t>(f.gcount()) != size) {
    why = "short read";
    return false;
  }
  return true;
}

namespace {

bool fs_file_exists(const std::string& filename, void* user) {
  auto* access = static_cast<FileAccess*>(user);
  std::string why;
  if (resolve_inside_root(*access, filename, why).empty()) {
    access->last_error = fs::path(filename).filename().string() + ": " + why;
    return false;
  }
  return true;
}

// No shell expansion (tinygltf's default runs wordexp on URIs).
std::string fs_expand(const std::string& path, void*) { return path; }

bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& filename, void* user) {
  auto* access = static_cast<FileAccess*>(user);
  std::string why;
  const fs::path resolved = resolve_inside_root(*access, filename, why);
  if (resolved.empty() || !read_file_capped(resolved, access->max_bytes, *out, why)) {
    access->last_error = filename + ": " + why;
    if (err) *err += access->last_error + "\n";
    return false;
  }
  return true;
}

bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "the importer never writes files\n";
  return false;
}

}  // namespace

namespace {
std::string percent_decode(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

std::string check_external_uris(const nlohmann::json& j, const FileAccess& access) {
  for (const char* array : {"buffers", "images"}) {
    const auto it = j.find(array);
    if (it == j.end() || !it->is_array()) continue;
    for (std::size_t i = 0; i < it->size(); ++i) {
      const auto& entry = (*it)[i];
      if (!entry.is_object() || !entry.contains("uri")) continue;
      const std::string field = std::string(array) + "[" + std::to_string(i) + "].uri";
      if (!entry["uri"].is_string()) return field + ": must be a string";
      const std::string uri = entry["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) continue;
      if (uri.find("://") != std::string::npos) return field + ": '" + uri + "' is not a relative file path";
      std::string why;
      if (resolve_inside_root(access, access.root / percent_decode(uri), why).empty())
        return field + ": '" + uri + "' " + why;
    }
  }
  return {};
}

// The bytes buffers[b] really has, or -1 when that cannot be told here
// (tinygltf then reports the buffer itself).
long long real_buffer_bytes(const nlohmann::json& buffer, std::size_t index, const FileAccess& access, std::size_t bin_length) {
  if (!buffer.is_object()) return -1;
  if (!buffer.contains("uri")) return index == 0 ? static_cast<long long>(bin_length) : 0;  // only buffer 0 may be the BIN chunk
  if (!buffer["uri"].is_string()) return -1;
  const std::string uri = buffer["uri"].get<std::string>();
  if (uri.rfind("data:", 0) == 0) {
    const std::size_t comma = uri.find(',');
    if (comma == std::string::npos) return 0;
    const std::size_t n = uri.size() - comma - 1;
    std::size_t pad = 0;
    while (pad < 2 && pad < n && uri[uri.size() - 1 - pad] == '=') ++pad;
    return static_cast<long long>((n - pad) * 3 / 4);  // base64: 3 bytes per 4 significant characters
  }
  std::string why;
  const std::filesystem::path file = resolve_inside_root(access, access.root / percent_decode(uri), why);
  std::error_code ec;
  const auto size = file.empty() ? 0 : std::filesystem::file_size(file, ec);
  return file.empty() || ec ? -1 : static_cast<long long>(size);
}

// A non-negative integer member, or `fallback` when absent; -1 when it is
// present but not one.
long long index_member(const nlohmann::json& o, const char* name, long long fallback) {
  if (!o.contains(name)) return fallback;
  const auto& v = o[name];
  if (v.is_number_unsigned()) return v.get<unsigned long long>() > (1ull << 62) ? -1 : static_cast<long long>(v.get<unsigned long long>());
  if (v.is_number_integer()) return v.get<long long>() < 0 ? -1 : v.get<long long>();
  return -1;
}

std::string check_image_buffer_views(const nlohmann::json& j, const FileAccess& access, std::size_t bin_length) {
  const auto images = j.find("images");
  if (images == j.end() || !images->is_array()) return {};
  const auto views = j.find("bufferViews");
  const auto buffers = j.find("buffers");
  for (std::size_t i = 0; i < images->size(); ++i) {
    const auto& image = (*images)[i];
    if (!image.is_object() || !image.contains("bufferView")) continue;
    const std::string field = "images[" + std::to_string(i) + "].bufferView";
    const long long v = index_member(image, "bufferView", -1);
    if (v < 0 || views == j.end() || !views->is_array() || static_cast<std::size_t>(v) >= views->size())
      return field + ": not the index of a bufferView";
    const auto& view = (*views)[static_cast<std::size_t>(v)];
    const std::string vfield = "bufferViews[" + std::to_string(v) + "]";
    if (!view.is_object()) return vfield + ": must be an object";
    const long long b = index_member(view, "buffer", -1), offset = index_member(view, "byteOffset", 0),
                    length = index_member(view, "byteLength", -1);
    if (b < 0 || buffers == j.end() || !buffers->is_array() || static_cast<std::size_t>(b) >= buffers->size())
      return vfield + ".buffer: not the index of a buffer";
    if (offset < 0 || length < 0) return vfield + ": byteOffset and byteLength must be non-negative integers";
    const auto& buffer = (*buffers)[static_cast<std::size_t>(b)];
    long long have = real_buffer_bytes(buffer, static_cast<std::size_t>(b), access, bin_length);
    // tinygltf keeps only the declared byteLength of a buffer (a BIN chunk
    // may be longer), and hands images a pointer into what it kept: both
    // bounds apply (found by the glTF fuzzer: a view inside the BIN chunk
    // but past byteLength read 989 bytes beyond the buffer).
    if (const long long declared = buffer.is_object() ? index_member(buffer, "byteLength", -1) : -1; declared >= 0)
      have = have < 0 ? declared : std::min(have, declared);
    if (have >= 0 && offset + length > have)
      return vfield + ": bytes [" + std::to_string(offset) + ", " + std::to_string(offset + length) + ") lie outside buffers[" +
             std::to_string(b) + "], which holds " + std::to_string(have) + " bytes (used by images[" + std::to_string(i) + "])";
  }
  return {};
}

}  // namespace

std::string json_syntax_error(std::string_view json_text) {
  try {
    [[maybe_unused]] const nlohmann::json parsed = nlohmann::json::parse(json_text);  // throws where it stops
    return {};
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the 1-based position where the parser stopped.
    const std::size_t at = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, json_text.size());
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < at; ++i) {
      if (json_text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    const std::string where = "line " + std::to_string(line) + ", column " + std::to_string(column);
    if (at >= json_text.size() || std::string_view(e.what()).find("unexpected end of input") != std::string_view::npos)
      return "the JSON ends at " + where + " (byte " + std::to_string(json_text.size()) +
             ") with objects or arrays still open: the file looks truncated";
    // The parser's own words after its "[json.exception...] " prefix.
    std::string why = e.what();
    if (const auto colon = why.find(": "); colon != std::string::npos) why = why.substr(colon + 2);
    if (const auto dash = why.find(" - "); dash != std::string::npos) why = why.substr(dash + 3);
    return "JSON syntax error at " + where + ": " + why;
  }
}

std::string check_references(std::string_view json_text, const FileAccess& access, std::size_t bin_length) {
  const auto j = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return json_syntax_error(json_text);
  if (!j.is_object()) return "the JSON's top level is not an object";
  if (std::string bad = check_external_uris(j, access); !bad.empty()) return bad;
  return check_image_buffer_views(j, access, bin_length);
}

tinygltf::FsCallbacks make_fs_callbacks(FileAccess* access) {
  tinygltf::FsCallbacks cb{};
  cb.FileExists = fs_file_exists;
  cb.ExpandFilePath = fs_expand;
  cb.ReadWholeFile = fs_read;
  cb.WriteWholeFile = fs_write;
  cb.user_data = access;
  return cb;
}

namespace {

// Walks a PNG's chunk list and checks that each chunk's declared length fits
// in the bytes left. stb_image grows its IDAT buffer to a chunk's declared
// length before reading it, so a 489-byte PNG claiming a 2 GB IDAT chunk
// made it allocate 2 GB (found by the image fuzzer).
std::string png_chunk_lengths_fit(const unsigned char* bytes, std::size_t size) {
  std::size_t at = 8;  // after the signature
  for (int chunk = 0; at + 8 <= size; ++chunk) {
    const std::uint32_t length = (std::uint32_t{bytes[at]} << 24) | (std::uint32_t{bytes[at + 1]} << 16) |
                                 (std::uint32_t{bytes[at + 2]} << 8) | std::uint32_t{bytes[at + 3]};
    const std::size_t left = size - at - 8;
    if (length > left)
      return "PNG chunk " + std::to_string(chunk) + " declares " + std::to_string(length) + " bytes but only " +
             std::to_string(left) + " follow (truncated or malformed PNG)";
    if (std::memcmp(bytes + at + 4, "IEND", 4) == 0) return {};
    at += 8 + static_cast<std::size_t>(length) + std::min<std::size_t>(4, left - length);  // + CRC
  }
  return {};
}

}  // namespace

bool load_image_checked(tinygltf::Image* image, int index, std::string* err, std::string*, int, int,
                        const unsigned char* bytes, int size, void* user) {
  const auto* limits = static_cast<const ImageLimits*>(user);
  const std::string where = "images[" + std::to_string(index) + "]";
  auto fail = [&](const std::string& why) {
    if (err) *err += where + ": " + why + "\n";
    return false;
  };
  static constexpr unsigned char kPng[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  static constexpr unsigned char kJpeg[3] = {0xFF, 0xD8, 0xFF};
  const bool png = size >= 8 && std::memcmp(bytes, kPng, 8) == 0;
  const bool jpeg = size >= 3 && std::memcmp(bytes, kJpeg, 3) == 0;
  if (!png && !jpeg) return fail("not a PNG or JPEG image (unrecognised magic bytes)");
  if (png)
    if (const std::string bad = png_chunk_lengths_fit(bytes, static_cast<std::size_t>(size)); !bad.empty()) return fail(bad);
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(bytes, size, &w, &h, &comp))
    return fail(std::string("malformed ") + (png ? "PNG" : "JPEG") + " header: " + stbi_failure_reason());
  if (w <= 0 || h <= 0 || w > limits->max_dimension || h > limits->max_dimension)
    return fail("image is " + std::to_string(w) + "x" + std::to_string(h) + ", over the limit of " +
                std::to_string(limits->max_dimension) + " per side");
  unsigned char* pixels = stbi_load_from_memory(bytes, size, &w, &h, &comp, 4);
  if (!pixels) return fail(std::string("cannot decode image data: ") + stbi_failure_reason());
  image->width = w;
  image->height = h;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image.assign(pixels, pixels + static_cast<std::size_t>(w) * h * 4);
  stbi_image_free(pixels);
  return true;
}

}  // namespace engine::scene::gltf_detail
