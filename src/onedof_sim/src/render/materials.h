// Gazebo's materials as the renderer draws them: a visual's VisualMaterial (the named material
// and the colours given) resolved to the ambient, diffuse and emissive colours it is lit with.
#pragma once

#include <string>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace render {

struct SurfaceColors {
  Color ambient, diffuse, emissive;
};

// The named material's colours (Gazebo's media/materials/scripts/gazebo.material: Gazebo/Red,
// Gazebo/Grey, Gazebo/Blue, ...; the textured ones as their pass's colours, without the
// texture), then the colours given explicitly over them, as Gazebo's Visual applies a script and
// then <ambient>, <diffuse>, <emissive>. No material at all: Gazebo's default, white. A
// <material> with colours and no script: SDF's defaults (black) for the colours not given.
// *known: false when the name is not one of Gazebo's materials the table has (drawn as if
// unnamed).
SurfaceColors resolveMaterial(const VisualMaterial& material, bool* known);

}  // namespace render
}  // namespace onedof_sim
