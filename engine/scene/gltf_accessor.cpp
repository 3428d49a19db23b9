#include "engine/scene/gltf_accessor.h"

#include <tiny_gltf.h>

#include <cstring>

#include "engine/scene/gltf_loader.h"

namespace engine::scene::gltf_detail {

namespace {
std::size_t component_size(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}
const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    default: return "another type";
  }
}
}  // namespace

void AccessorReader::fail(const std::string& field, const std::string& why) const {
  throw GltfError(file + ": " + field + ": " + why);
}

AccessorReader::Layout AccessorReader::layout(int index, const std::string& field, int expected_type,
                                              std::size_t components) const {
  const std::string acc_field = field + " (accessors[" + std::to_string(index) + "])";
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
    fail(field, "accessor index " + std::to_string(index) + " is out of range (" +
                    std::to_string(model.accessors.size()) + " accessors)");
  const tinygltf::Accessor& a = model.accessors[static_cast<std::size_t>(index)];
  if (a.sparse.isSparse) fail(acc_field, "sparse accessors are not supported");
  if (a.type != expected_type)
    fail(acc_field, std::string("type must be ") + type_name(expected_type) + ", got " + type_name(a.type));
  const std::size_t csize = component_size(a.componentType);
  if (csize == 0) fail(acc_field, "unknown componentType " + std::to_string(a.componentType));
  if (a.count == 0) fail(acc_field, "count is 0");
  Layout l;
  l.count = a.count;
  l.component_type = a.componentType;
  l.normalized = a.normalized;
  const std::size_t elem = csize * components;
  if (a.bufferView < 0) {
    l.stride = elem;  // the spec says: all zeros
    return l;
  }
  if (static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size())
    fail(acc_field, "bufferView " + std::to_string(a.bufferView) + " is out of range (" +
                        std::to_string(model.bufferViews.size()) + " bufferViews)");
  const tinygltf::BufferView& v = model.bufferViews[static_cast<std::size_t>(a.bufferView)];
  const std::string view_field = "bufferViews[" + std::to_string(a.bufferView) + "]";
  if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= model.buffers.size())
    fail(view_field, "buffer " + std::to_string(v.buffer) + " is out of range (" + std::to_string(model.buffers.size()) +
                         " buffers)");
  const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(v.buffer)].data;
  if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
    fail(view_field, "byteOffset " + std::to_string(v.byteOffset) + " + byteLength " + std::to_string(v.byteLength) +
                         " runs past the end of buffers[" + std::to_string(v.buffer) + "] (" +
                         std::to_string(data.size()) + " bytes)");
  l.stride = v.byteStride ? v.byteStride : elem;
  if (l.stride < elem) fail(view_field, "byteStride " + std::to_string(l.stride) + " is smaller than one element (" +
                                            std::to_string(elem) + " bytes)");
  // Overflow-safe: count and stride are both bounded by the buffer size below.
  if (a.byteOffset > v.byteLength || l.count > (v.byteLength - a.byteOffset) / l.stride + 1 ||
      a.byteOffset + (l.count - 1) * l.stride + elem > v.byteLength)
    fail(acc_field, "byteOffset " + std::to_string(a.byteOffset) + " + " + std::to_string(l.count) +
                        " elements of stride " + std::to_string(l.stride) + " runs past the end of " + view_field + " (" +
                        std::to_string(v.byteLength) + " bytes)");
  l.base = data.data() + v.byteOffset + a.byteOffset;
  return l;
}

std::vector<glm::vec3> AccessorReader::vec3(int index, const std::string& field) const {
  const Layout l = layout(index, field, TINYGLTF_TYPE_VEC3, 3);
  if (l.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT)
    fail(field, "componentType must be FLOAT (5126), got " + std::to_string(l.component_type));
  std::vector<glm::vec3> out(l.count, glm::vec3(0.0f));
  if (l.base)
    for (std::size_t i = 0; i < l.count; ++i) std::memcpy(&out[i], l.base + i * l.stride, sizeof(glm::vec3));
  return out;
}

std::vector<glm::vec2> AccessorReader::vec2(int index, const std::string& field) const {
  const Layout l = layout(index, field, TINYGLTF_TYPE_VEC2, 2);
  std::vector<glm::vec2> out(l.count, glm::vec2(0.0f));
  if (!l.base) return out;
  for (std::size_t i = 0; i < l.count; ++i) {
    const unsigned char* p = l.base + i * l.stride;
    switch (l.component_type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT:
        std::memcpy(&out[i], p, sizeof(glm::vec2));
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        if (!l.normalized) fail(field, "UNSIGNED_BYTE texture coordinates must be normalized");
        out[i] = glm::vec2(p[0], p[1]) / 255.0f;
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        if (!l.normalized) fail(field, "UNSIGNED_SHORT texture coordinates must be normalized");
        std::uint16_t s[2];
        std::memcpy(s, p, sizeof(s));
        out[i] = glm::vec2(s[0], s[1]) / 65535.0f;
        break;
      }
      default:
        fail(field, "componentType " + std::to_string(l.component_type) + " is not allowed for texture coordinates");
    }
  }
  return out;
}

std::vector<std::uint32_t> AccessorReader::indices(int index, const std::string& field) const {
  const Layout l = layout(index, field, TINYGLTF_TYPE_SCALAR, 1);
  std::vector<std::uint32_t> out(l.count, 0);
  if (!l.base) return out;
  for (std::size_t i = 0; i < l.count; ++i) {
    const unsigned char* p = l.base + i * l.stride;
    switch (l.component_type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        out[i] = p[0];
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        std::uint16_t v;
        std::memcpy(&v, p, 2);
        out[i] = v;
        break;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        std::memcpy(&out[i], p, 4);
        break;
      default:
        fail(field, "index componentType must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT, got " +
                        std::to_string(l.component_type));
    }
  }
  return out;
}

}  // namespace engine::scene::gltf_detail
