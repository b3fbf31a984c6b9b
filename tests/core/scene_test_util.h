// Helpers shared by the scene/loader tests: temporary folders, file writing, and
// geometric oracles (triangle area and winding).
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include <glm/geometric.hpp>

#include "core/scene.h"

namespace speculum::testing {

// A fresh folder unique to this process and `tag` (ctest runs tests in parallel).
inline std::filesystem::path temp_dir(const std::string& tag) {
  auto dir = std::filesystem::temp_directory_path() /
             ("speculum_test_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

inline glm::vec3 triangle_cross(const Scene& s, std::size_t t) {
  const auto& m = s.mesh;
  const glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                  c = m.positions[m.indices[3 * t + 2]];
  return glm::cross(b - a, c - a);
}

inline double total_area(const Scene& s) {
  double a = 0.0;
  for (std::size_t t = 0; t < s.mesh.triangle_count(); ++t) a += 0.5 * glm::length(triangle_cross(s, t));
  return a;
}

}  // namespace speculum::testing
