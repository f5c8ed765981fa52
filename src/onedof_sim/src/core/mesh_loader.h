// Triangle meshes for collision shapes: a mesh file's URI resolved as Gazebo resolves it, the
// file read with assimp (STL, COLLADA and the other formats it reads), scaled. Private to the core.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

// TriangleMesh (onedof_sim/world.h) is a mesh ready for the engines: vertices already scaled
// into the collision frame. Immutable and shared: the engines keep pointers into it for as long
// as a model lives.

// The file a mesh URI names, as Gazebo finds it: model://NAME/... in the first folder of the
// model path that has NAME/...; package://PKG/... the same way (Gazebo's URDF conversion turns
// package:// into model://; the ROS layer has already replaced the package:// URIs of a URDF by
// the packages' folders, as gazebo_ros does); file:// and absolute paths as they are; a relative
// path from `relative_to` (the folder of the SDF file that holds it; empty: not resolved). A
// model:// or package:// path is confined to the model path's folders: one that leaves its
// folder once normalised (`..`, an absolute path) names no file. Empty when no readable regular
// file is found: a missing file, an unreadable one, a folder and a device are alike to the
// caller, who learns nothing of which files exist.
// Whether `relative`, once normalised, stays below the folder it is taken from: not absolute,
// no `..` climbing out. What confines model:// and package:// paths to the model path.
bool staysInside(const std::string& relative);

std::string resolveMeshUri(const std::string& uri, const std::vector<std::string>& model_path,
                           const std::string& relative_to);

// Reads the mesh files of one model, each file once however many collisions use it.
class MeshReader {
 public:
  struct Limits {
    size_t file_bytes = 0;
    size_t mesh_triangles = 0;
    size_t model_triangles = 0;
    size_t placements = 0;  // nodes and geometry instances a file places (mesh_precheck.h)
    size_t depth = 0;       // levels its nodes nest
  };
  // Collision meshes: the Limits of model_description.h.
  MeshReader();
  explicit MeshReader(const Limits& limits) : limits_(limits) {}
  // The mesh of `file` scaled by `scale` (each component finite and non-zero), or a
  // ModelRejected status with the reason: a file of a format other than STL, COLLADA and OBJ,
  // one past the limit's file_bytes (checked before it is read), one whose structure
  // (measureMesh, before assimp reads it) places more than mesh_triangles triangles or
  // `placements` nodes, nests deeper than `depth` or instances a node within itself, one assimp
  // cannot read (assimp's reason), one without triangles, or one that takes the model's meshes
  // past model_triangles (checked before the next file is read).
  Status read(const std::string& file, const Vec3& scale, std::shared_ptr<const TriangleMesh>* out);

 private:
  struct Raw {
    std::vector<Vec3> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
  };
  Status readRaw(const std::string& file, std::shared_ptr<const Raw>* out);
  Limits limits_;
  std::map<std::string, std::shared_ptr<const Raw>> files_;
  size_t model_triangles_ = 0;  // of every mesh read, each time it is read
};

}  // namespace core
}  // namespace onedof_sim
