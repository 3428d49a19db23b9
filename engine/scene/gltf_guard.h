#pragma once
// Pre-parse checks and file access for the glTF importer (internal).
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tinygltf {
struct FsCallbacks;
struct Image;
}

namespace engine::scene::gltf_detail {

// Deepest nesting of JSON arrays/objects in text (strings are skipped).
int json_depth(std::string_view text);

struct GlbChunks {
  std::string_view json;
  std::size_t bin_offset = 0;  // 0 when there is no BIN chunk
  std::size_t bin_length = 0;
};
// Validates the GLB header and chunk table; throws std::runtime_error with
// the offending field.
GlbChunks parse_glb(const std::vector<unsigned char>& bytes);

struct FileAccess {
  std::filesystem::path root;  // canonical scene folder
  std::uint64_t max_bytes = 0;
  std::string last_error;      // why the last refused access was refused
};

// Resolves `path` and checks it is a regular file inside root; returns the
// canonical path or an empty path with `why` set.
std::filesystem::path resolve_inside_root(const FileAccess& access, const std::filesystem::path& path, std::string& why);
// Reads a whole regular file, refusing anything over max_bytes.
bool read_file_capped(const std::filesystem::path& path, std::uint64_t max_bytes, std::vector<unsigned char>& out,
                      std::string& why);

tinygltf::FsCallbacks make_fs_callbacks(FileAccess* access);

// Checks, on one parse of the JSON, before tinygltf sees it:
//  - every external buffers[i].uri and images[i].uri (data: URIs are
//    skipped) names a regular file inside the scene's folder;
//  - every images[i].bufferView lies inside the bytes its buffer really has
//    (the GLB BIN chunk, a data: URI's decoded length or the file's size), as
//    the declared byteLength alone does not: tinygltf hands the image decoder
//    a pointer to bufferView.byteOffset without checking it.
// Returns "field: reason" for the first bad one, or an empty string. The JSON
// must already have passed json_depth. bin_length: the GLB's BIN chunk length
// (0 for .gltf).
// A JSON syntax error also comes back from it, as json_syntax_error says it.
std::string check_references(std::string_view json, const FileAccess& access, std::size_t bin_length);

// Where the JSON text stops parsing, in words: "the JSON ends at line L,
// column C ... truncated" for a cut-off file, "JSON syntax error at line L,
// column C: why" otherwise; empty for valid JSON.
std::string json_syntax_error(std::string_view json);

struct ImageLimits {
  int max_dimension = 16384;
};
// tinygltf image callback: PNG/JPEG by magic bytes, size-capped, RGBA8 out.
bool load_image_checked(tinygltf::Image* image, int index, std::string* err, std::string* warn, int req_w, int req_h,
                        const unsigned char* bytes, int size, void* user);

}  // namespace engine::scene::gltf_detail
