// Axis-aligned bounds of a mesh file's vertices, so that a mesh collision can stand in as its
// bounding box (the engines collide boxes, cylinders and spheres only). Private to the core.
#pragma once

#include <string>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

struct MeshBounds {
  Vec3 min, max;  // in the mesh's own frame and units
};

// Reads STL (ASCII or binary) and OBJ vertices. False, with *error set, for another format, a
// file that cannot be read, or one without vertices.
bool readMeshBounds(const std::string& path, MeshBounds* bounds, std::string* error);

}  // namespace core
}  // namespace onedof_sim
