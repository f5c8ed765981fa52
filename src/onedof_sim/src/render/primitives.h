// The shapes the renderer draws, as triangle lists of (position, normal) vertices, six floats
// each: unit shapes the model matrix scales (box: a unit cube about its centre; cylinder: radius
// 1, length 1 along z, centred; sphere: radius 1; plane: a unit square in xy, normal +z), and a
// mesh as it is (its vertices already scaled), flat-shaded.
#pragma once

#include <vector>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace render {

std::vector<float> unitShapeVertices(GeometryShape shape);  // not Mesh
std::vector<float> meshVertices(const TriangleMesh& mesh);

}  // namespace render
}  // namespace onedof_sim
