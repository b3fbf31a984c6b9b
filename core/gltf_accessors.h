// Checked access to glTF accessors: every index, range, stride, type and count is
// validated against the actual buffer bytes before anything is read (glTF 2.0 §3.6).
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace speculum::gltf {

// Largest element count we accept for one accessor: far above any real asset, far below
// what would overflow byte arithmetic or exhaust memory ("absurd counts").
constexpr std::size_t kMaxAccessorCount = std::size_t{1} << 28;

// A validated accessor: `data` points at element 0 (nullptr: all zeros, no bufferView).
// A sparse accessor (glTF 2.0 §3.6.2.3) replaces the elements `sparse_indices` (strictly
// increasing, each below count) with the tightly packed elements at `sparse_values`.
struct AccessorView {
  const unsigned char* data = nullptr;
  std::size_t count = 0;
  std::size_t stride = 0;
  int components = 0;
  int component_type = 0;
  bool normalized = false;
  std::vector<std::uint32_t> sparse_indices;
  const unsigned char* sparse_values = nullptr;
};

// Validates accessor `index` for use as `what` (e.g. "POSITION of mesh 'x' primitive 0")
// with one of `types` (TINYGLTF_TYPE_*) and `component_types`. Throws InputError(path).
AccessorView checked_accessor(const tinygltf::Model& model, int index, const std::string& path,
                              const std::string& what, std::initializer_list<int> types,
                              std::initializer_list<int> component_types);

// Element values as floats (count * components), normalised integers mapped per glTF.
std::vector<float> read_floats(const AccessorView& view);

// Unsigned integer elements (index buffers).
std::vector<std::uint32_t> read_indices(const AccessorView& view);

}  // namespace speculum::gltf
