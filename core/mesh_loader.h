// PLY / STL meshes through OpenMesh, OFF through core/off_reader.h: one object, one default material, normals from
// the file or computed (area-weighted). OBJ, which carries materials, goes to load_obj
// (core/obj_loader.h).
#pragma once

#include <string>

#include "core/scene.h"
#include "core/scene_loader.h"

namespace speculum {

// Throws InputError(path, problem) for missing, empty, truncated or malformed files.
Scene load_mesh_file(const std::string& path, LoadReport* report = nullptr);

}  // namespace speculum
