// A mesh file's structure measured from its bytes before assimp reads them: the triangles it
// places (after triangulation, each placement of a shared geometry counted), the nodes and
// geometry instances it places, and how deep its node hierarchy nests, with a COLLADA node
// that instances itself (directly or through others) found as a cycle. assimp builds a COLLADA
// hierarchy by recursion and copies an instanced node for each placement, so a deep or
// self-instancing file overflows its stack and an instance fan-out spends memory exponential
// in the file's size; these are refused here, where the measure takes memory linear in the
// file's size and no recursion. Private to the core.
#pragma once

#include <cstddef>
#include <string>

namespace onedof_sim {
namespace core {

// The formats Gazebo classic's MeshManager reads, told by the file name's extension in any
// case: .stl, .dae and .obj. assimp picks its importer by that extension too.
enum class MeshFormat { Unknown, Stl, Collada, Obj };
MeshFormat meshFormatOf(const std::string& file);
// The extension assimp is told the bytes have ("stl", "dae", "obj"); empty for Unknown.
const char* meshFormatExtension(MeshFormat format);

struct MeshShapeLimits {
  size_t triangles = 0;   // placed triangles
  size_t placements = 0;  // placed nodes and geometry instances
  size_t depth = 0;       // nested nodes, instances followed; for COLLADA also XML elements
};

enum class MeshShapeCode {
  Ok,
  NotWellFormed,      // subject: the XML parser's reason
  TooDeep,            // subject: what nests ("nodes", "XML elements"); depth: how deep
  InstanceCycle,      // subject: the node ids around the cycle, "a -> b -> a"
  TooManyPlacements,  // placements
  TooManyTriangles,   // triangles
};

struct MeshShape {
  MeshShapeCode code = MeshShapeCode::Ok;
  // Counts saturate far above any limit, so that a fan-out of 4^40 is still a number.
  size_t triangles = 0;
  size_t placements = 0;
  size_t depth = 0;
  std::string subject;
};

// The shape of `bytes`, a file of `format` (not Unknown), against the limits. Ok when within
// them, or when the file is not one assimp would read (assimp then says why).
MeshShape measureMesh(const std::string& bytes, MeshFormat format, const MeshShapeLimits& limits);

}  // namespace core
}  // namespace onedof_sim
