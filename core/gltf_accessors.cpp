// Checked glTF accessor reading (see gltf_accessors.h).
#include "core/gltf_accessors.h"

#include <algorithm>
#include <cstring>

#include "core/error.h"

namespace speculum::gltf {
namespace {

int component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

template <class T>
T load(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

}  // namespace

AccessorView checked_accessor(const tinygltf::Model& model, int index, const std::string& path,
                              const std::string& what, std::initializer_list<int> types,
                              std::initializer_list<int> component_types) {
  auto fail = [&](const std::string& problem) {
    throw InputError(path, what + ": accessor " + std::to_string(index) + " " + problem);
  };
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
    throw InputError(path, what + ": accessor index " + std::to_string(index) +
                               " out of range (" + std::to_string(model.accessors.size()) +
                               " accessors)");
  const tinygltf::Accessor& acc = model.accessors[static_cast<std::size_t>(index)];
  const int csize = component_size(acc.componentType);
  const int ncomp = type_components(acc.type);
  if (csize == 0) fail("has invalid componentType " + std::to_string(acc.componentType));
  if (ncomp == 0) fail("has invalid type " + std::to_string(acc.type));
  if (std::find(types.begin(), types.end(), acc.type) == types.end())
    fail("has the wrong type for this attribute");
  if (std::find(component_types.begin(), component_types.end(), acc.componentType) ==
      component_types.end())
    fail("has the wrong componentType " + std::to_string(acc.componentType) +
         " for this attribute");
  if (acc.count > kMaxAccessorCount)
    fail("has an absurd count " + std::to_string(acc.count) + " (more than the limit of 2^28)");
  if (acc.sparse.isSparse) fail("is sparse (sparse accessors are not supported)");

  AccessorView view;
  view.count = acc.count;
  view.components = ncomp;
  view.component_type = acc.componentType;
  view.normalized = acc.normalized;
  const std::size_t elem = static_cast<std::size_t>(csize) * static_cast<std::size_t>(ncomp);
  view.stride = elem;
  if (acc.bufferView < 0) return view;  // all zeros (glTF §3.6.2.3)

  if (static_cast<std::size_t>(acc.bufferView) >= model.bufferViews.size())
    fail("names bufferView " + std::to_string(acc.bufferView) + " which does not exist");
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(acc.bufferView)];
  if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size())
    fail("uses bufferView " + std::to_string(acc.bufferView) + " naming a missing buffer");
  const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(bv.buffer)].data;
  if (bv.byteLength > data.size() || bv.byteOffset > data.size() - bv.byteLength)
    fail("uses bufferView " + std::to_string(acc.bufferView) + " which runs past the end of " +
         "its buffer (" + std::to_string(data.size()) + " bytes)");
  if (bv.byteStride != 0) {
    if (bv.byteStride < elem || bv.byteStride > 252)
      fail("has an invalid byteStride " + std::to_string(bv.byteStride));
    view.stride = bv.byteStride;
  }
  if (view.count > 0) {
    // count <= 2^28 and stride <= 252: the product cannot overflow 64 bits.
    const std::size_t span = view.stride * (view.count - 1) + elem;
    if (acc.byteOffset > bv.byteLength || span > bv.byteLength - acc.byteOffset)
      fail("reads past the end of bufferView " + std::to_string(acc.bufferView) + " (count " +
           std::to_string(view.count) + ", " + std::to_string(bv.byteLength) + " bytes)");
  }
  view.data = data.data() + bv.byteOffset + acc.byteOffset;
  return view;
}

std::vector<float> read_floats(const AccessorView& v) {
  const std::size_t n = v.count * static_cast<std::size_t>(v.components);
  std::vector<float> out(n, 0.0f);
  if (!v.data) return out;
  const int csize = component_size(v.component_type);
  for (std::size_t i = 0; i < v.count; ++i) {
    const unsigned char* e = v.data + i * v.stride;
    for (int c = 0; c < v.components; ++c) {
      const unsigned char* p = e + c * csize;
      float x = 0.0f;
      switch (v.component_type) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: x = load<float>(p); break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          x = v.normalized ? load<std::uint8_t>(p) / 255.0f : load<std::uint8_t>(p);
          break;
        case TINYGLTF_COMPONENT_TYPE_BYTE:
          x = v.normalized ? std::max(load<std::int8_t>(p) / 127.0f, -1.0f)
                           : load<std::int8_t>(p);
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
          x = v.normalized ? load<std::uint16_t>(p) / 65535.0f : load<std::uint16_t>(p);
          break;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
          x = v.normalized ? std::max(load<std::int16_t>(p) / 32767.0f, -1.0f)
                           : load<std::int16_t>(p);
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
          x = static_cast<float>(load<std::uint32_t>(p));
          break;
        default: break;
      }
      out[i * static_cast<std::size_t>(v.components) + static_cast<std::size_t>(c)] = x;
    }
  }
  return out;
}

std::vector<std::uint32_t> read_indices(const AccessorView& v) {
  std::vector<std::uint32_t> out(v.count, 0u);
  if (!v.data) return out;
  for (std::size_t i = 0; i < v.count; ++i) {
    const unsigned char* p = v.data + i * v.stride;
    switch (v.component_type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: out[i] = load<std::uint8_t>(p); break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: out[i] = load<std::uint16_t>(p); break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: out[i] = load<std::uint32_t>(p); break;
      default: break;
    }
  }
  return out;
}

}  // namespace speculum::gltf
