#pragma once
// Range-checked reads of glTF accessors (internal to the importer). Every
// offset, stride and count is validated against its bufferView and buffer
// before a single byte is read; failures name the accessor.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace tinygltf {
class Model;
}

namespace engine::scene::gltf_detail {

struct AccessorReader {
  const tinygltf::Model& model;
  std::string file;  // for messages

  // FLOAT VEC3.
  std::vector<glm::vec3> vec3(int accessor, const std::string& field) const;
  // FLOAT, or normalized UNSIGNED_BYTE / UNSIGNED_SHORT, VEC2.
  std::vector<glm::vec2> vec2(int accessor, const std::string& field) const;
  // UNSIGNED_BYTE / UNSIGNED_SHORT / UNSIGNED_INT SCALAR.
  std::vector<std::uint32_t> indices(int accessor, const std::string& field) const;

 private:
  struct Layout {
    const unsigned char* base = nullptr;  // null = zero-filled (no bufferView)
    std::size_t stride = 0;
    std::size_t count = 0;
    int component_type = 0;
    bool normalized = false;
  };
  Layout layout(int accessor, const std::string& field, int expected_type, std::size_t components) const;
  [[noreturn]] void fail(const std::string& field, const std::string& why) const;
};

}  // namespace engine::scene::gltf_detail
