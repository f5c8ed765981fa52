#include "materials.h"

#include <map>

namespace onedof_sim {
namespace render {
namespace {

SurfaceColors colors(Color ambient, Color diffuse, Color emissive = {0, 0, 0, 1}) {
  return {ambient, diffuse, emissive};
}

Color grey(float v) { return {v, v, v, 1}; }

// The pass colours of Gazebo's gazebo.material (ambient, diffuse, emissive).
const std::map<std::string, SurfaceColors>& namedMaterials() {
  static const std::map<std::string, SurfaceColors> table = {
      {"Gazebo/Grey", colors(grey(0.3f), grey(0.7f))},
      {"Gazebo/DarkGrey", colors(grey(0.175f), grey(0.175f))},
      {"Gazebo/White", colors(grey(1), grey(1))},
      {"Gazebo/FlatBlack", colors(grey(0.1f), grey(0.1f))},
      {"Gazebo/Black", colors(grey(0), grey(0))},
      {"Gazebo/Red", colors({1, 0, 0, 1}, {1, 0, 0, 1})},
      {"Gazebo/RedBright", colors({0.87f, 0.26f, 0.07f, 1}, {0.87f, 0.26f, 0.07f, 1})},
      {"Gazebo/Green", colors({0, 1, 0, 1}, {0, 1, 0, 1})},
      {"Gazebo/Blue", colors({0, 0, 1, 1}, {0, 0, 1, 1})},
      {"Gazebo/SkyBlue", colors({0.13f, 0.44f, 0.70f, 1}, {0, 0, 1, 1})},
      {"Gazebo/Yellow", colors({1, 1, 0, 1}, {1, 1, 0, 1})},
      {"Gazebo/ZincYellow", colors({0.9725f, 0.9529f, 0.2078f, 1}, {0.9725f, 0.9529f, 0.2078f, 1})},
      {"Gazebo/Purple", colors({1, 0, 1, 1}, {1, 0, 1, 1})},
      {"Gazebo/Turquoise", colors({0, 1, 1, 1}, {0, 1, 1, 1})},
      {"Gazebo/Orange", colors({1, 0.5088f, 0.0468f, 1}, {1, 0.5088f, 0.0468f, 1})},
      {"Gazebo/Gold", colors({0.4f, 0.24869f, 0.020759f, 1}, {0.8f, 0.64869f, 0.120759f, 1})},
      {"Gazebo/WhiteGlow", colors(grey(1), grey(1), grey(1))},
      {"Gazebo/RedGlow", colors({1, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, 1})},
      {"Gazebo/GreenGlow", colors({0, 1, 0, 1}, {0, 1, 0, 1}, {0, 1, 0, 1})},
      {"Gazebo/BlueGlow", colors({0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1})},
      {"Gazebo/YellowGlow", colors({1, 1, 0, 1}, {1, 1, 0, 1}, {1, 1, 0, 1})},
      {"Gazebo/PurpleGlow", colors({1, 0, 1, 1}, {1, 0, 1, 1}, {1, 0, 1, 1})},
      {"Gazebo/TurquoiseGlow", colors({0, 1, 1, 1}, {0, 1, 1, 1}, {0, 1, 1, 1})},
      {"Gazebo/Wood", colors(grey(1), grey(1))},
      {"Gazebo/WoodPallet", colors(grey(0.5f), grey(1))},
      {"Gazebo/Road", colors(grey(0.1f), grey(0.8f))},
  };
  return table;
}

}  // namespace

SurfaceColors resolveMaterial(const VisualMaterial& material, bool* known) {
  *known = true;
  const bool any_color = material.ambient || material.diffuse || material.emissive;
  SurfaceColors out = any_color ? colors(grey(0), grey(0)) : colors(grey(1), grey(1));
  if (!material.script.empty()) {
    const auto named = namedMaterials().find(material.script);
    if (named != namedMaterials().end())
      out = named->second;
    else
      *known = false;
  }
  if (material.ambient) out.ambient = *material.ambient;
  if (material.diffuse) out.diffuse = *material.diffuse;
  if (material.emissive) out.emissive = *material.emissive;
  return out;
}

}  // namespace render
}  // namespace onedof_sim
