// Checked glTF accessor reading (see gltf_accessors.h).
#include "core/gltf_accessors.h"

#include <algorithm>
#include <cstring>
#include <functional>

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

// The bytes [byteOffset, byteOffset + bytes) of bufferView `view` after the checks every
// use of a bufferView needs: the view names a buffer and lies inside it, and the first byte
// is aligned to the component size (glTF 2.0 §3.6.2.4 "Data alignment": the accessor's
// offset and the sum of both offsets are multiples of the component size).
const unsigned char* checked_range(const tinygltf::Model& model, int view, std::size_t byte_offset,
                                   std::size_t bytes, int csize, const std::function<void(const std::string&)>& fail,
                                   const std::string& role) {
  if (view < 0 || static_cast<std::size_t>(view) >= model.bufferViews.size())
    fail(role + "names bufferView " + std::to_string(view) + " which does not exist");
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(view)];
  if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size())
    fail(role + "uses bufferView " + std::to_string(view) + " naming a missing buffer");
  const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(bv.buffer)].data;
  if (bv.byteLength > data.size() || bv.byteOffset > data.size() - bv.byteLength)
    fail(role + "uses bufferView " + std::to_string(view) + " which runs past the end of " +
         "its buffer (" + std::to_string(data.size()) + " bytes)");
  if (byte_offset % static_cast<std::size_t>(csize) != 0 ||
      (bv.byteOffset + byte_offset) % static_cast<std::size_t>(csize) != 0)
    fail(role + "byteOffset " + std::to_string(byte_offset) + " (bufferView " + std::to_string(view) +
         " at " + std::to_string(bv.byteOffset) + ") is not a multiple of its component size " +
         std::to_string(csize));
  if (byte_offset > bv.byteLength || bytes > bv.byteLength - byte_offset)
    fail(role + "reads past the end of bufferView " + std::to_string(view) + " (" +
         std::to_string(bytes) + " bytes at " + std::to_string(byte_offset) + ", the view has " +
         std::to_string(bv.byteLength) + ")");
  return data.data() + bv.byteOffset + byte_offset;
}

std::uint32_t load_index(const unsigned char* p, int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load<std::uint8_t>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load<std::uint16_t>(p);
    default: return load<std::uint32_t>(p);
  }
}

// The sparse part of `acc` (glTF 2.0 §3.6.2.3): its indices unsigned, strictly increasing
// and below the accessor's count, both byte ranges inside their bufferViews, which must not
// define byteStride (the data are tightly packed).
void read_sparse(const tinygltf::Model& model, const tinygltf::Accessor& acc, std::size_t elem, int csize,
                 const std::function<void(const std::string&)>& fail, AccessorView& view) {
  const auto& sp = acc.sparse;
  if (sp.count < 1 || static_cast<std::size_t>(sp.count) > acc.count)
    fail("has sparse.count " + std::to_string(sp.count) + " outside [1, count " + std::to_string(acc.count) + "]");
  if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0) fail("has a negative sparse byteOffset");
  const int icsize = sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 1
                     : sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
                     : sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT   ? 4
                                                                                          : 0;
  if (icsize == 0)
    fail("has sparse.indices.componentType " + std::to_string(sp.indices.componentType) +
         " (must be an unsigned byte, short or int)");
  for (int v : {sp.indices.bufferView, sp.values.bufferView})
    if (v >= 0 && static_cast<std::size_t>(v) < model.bufferViews.size() &&
        model.bufferViews[static_cast<std::size_t>(v)].byteStride != 0)
      fail("has sparse data in bufferView " + std::to_string(v) + ", which must not define byteStride");
  const std::size_t n = static_cast<std::size_t>(sp.count);
  const unsigned char* idx = checked_range(model, sp.indices.bufferView, static_cast<std::size_t>(sp.indices.byteOffset),
                                           n * static_cast<std::size_t>(icsize), icsize, fail, "sparse.indices ");
  view.sparse_values = checked_range(model, sp.values.bufferView, static_cast<std::size_t>(sp.values.byteOffset),
                                     n * elem, csize, fail, "sparse.values ");
  view.sparse_indices.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = load_index(idx + k * static_cast<std::size_t>(icsize), sp.indices.componentType);
    if (i >= acc.count) fail("has sparse index " + std::to_string(i) + " out of range (count " + std::to_string(acc.count) + ")");
    if (k > 0 && i <= view.sparse_indices[k - 1])
      fail("has sparse indices that are not strictly increasing (" + std::to_string(view.sparse_indices[k - 1]) +
           " then " + std::to_string(i) + ")");
    view.sparse_indices[k] = i;
  }
}

}  // namespace

AccessorView checked_accessor(const tinygltf::Model& model, int index, const std::string& path,
                              const std::string& what, std::initializer_list<int> types,
                              std::initializer_list<int> component_types) {
  const std::function<void(const std::string&)> fail = [&](const std::string& problem) {
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
  // glTF 2.0 §5.1 accessor.normalized: "MUST NOT be set to true for accessors with FLOAT or
  // UNSIGNED_INT component type".
  if (acc.normalized && (acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                         acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
    fail("is normalized with a float or unsigned int componentType");
  if (acc.count > kMaxAccessorCount)
    fail("has an absurd count " + std::to_string(acc.count) + " (more than the limit of 2^28)");

  AccessorView view;
  view.count = acc.count;
  view.components = ncomp;
  view.component_type = acc.componentType;
  view.normalized = acc.normalized;
  const std::size_t elem = static_cast<std::size_t>(csize) * static_cast<std::size_t>(ncomp);
  view.stride = elem;
  if (acc.sparse.isSparse) read_sparse(model, acc, elem, csize, fail, view);
  if (acc.bufferView < 0) return view;  // all zeros (glTF §3.6.2.3)

  if (static_cast<std::size_t>(acc.bufferView) >= model.bufferViews.size())
    fail("names bufferView " + std::to_string(acc.bufferView) + " which does not exist");
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(acc.bufferView)];
  if (bv.byteStride != 0) {
    // glTF 2.0 §3.6.2.4: a stride is a multiple of the component size, at least one element.
    if (bv.byteStride < elem || bv.byteStride > 252 || bv.byteStride % static_cast<std::size_t>(csize) != 0)
      fail("has an invalid byteStride " + std::to_string(bv.byteStride) + " for " + std::to_string(elem) +
           "-byte elements of " + std::to_string(csize) + "-byte components");
    view.stride = bv.byteStride;
  }
  // count <= 2^28 and stride <= 252: the span cannot overflow 64 bits.
  const std::size_t span = view.count > 0 ? view.stride * (view.count - 1) + elem : 0;
  view.data = checked_range(model, acc.bufferView, acc.byteOffset, span, csize, fail, "");
  return view;
}

std::vector<float> read_floats(const AccessorView& v) {
  const std::size_t n = v.count * static_cast<std::size_t>(v.components);
  std::vector<float> out(n, 0.0f);
  const int csize = component_size(v.component_type);
  const std::size_t elem = static_cast<std::size_t>(csize) * static_cast<std::size_t>(v.components);
  const std::size_t dense = v.data ? v.count : 0;
  for (std::size_t k = 0; k < dense + v.sparse_indices.size(); ++k) {
    // The dense elements, then the sparse ones over them.
    const std::size_t i = k < dense ? k : v.sparse_indices[k - dense];
    const unsigned char* e = k < dense ? v.data + i * v.stride : v.sparse_values + (k - dense) * elem;
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
  if (v.data)
    for (std::size_t i = 0; i < v.count; ++i) out[i] = load_index(v.data + i * v.stride, v.component_type);
  const std::size_t elem = static_cast<std::size_t>(component_size(v.component_type));
  for (std::size_t k = 0; k < v.sparse_indices.size(); ++k)
    out[v.sparse_indices[k]] = load_index(v.sparse_values + k * elem, v.component_type);
  return out;
}

}  // namespace speculum::gltf
