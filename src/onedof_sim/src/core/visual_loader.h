// A link's <visual>s (geometry, pose in the link frame, material) for World::visualShapes, read
// from URDF (urdfdom, and Gazebo's named materials from the URDF's <gazebo reference> blocks:
// urdf_extensions.h) and SDF (libsdformat). A visual never makes a model refused: a
// mesh file not found keeps its URI and an empty file, for the renderer to report. Private to
// the core.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <sdf/sdf.hh>
#include <urdf_model/link.h>

#include "model_description.h"

namespace onedof_sim {
namespace core {

// Appends the link's visuals to link->visuals. gazebo_material: the Gazebo material its
// <gazebo reference> names (urdf_extensions.h), or empty.
void addUrdfVisuals(const urdf::Link& urdf_link, const std::string& gazebo_material,
                    const std::vector<std::string>& model_path, LinkDescription* link);

// Appends the link's visuals to link->visuals; false (and *error) when libsdformat cannot
// resolve a visual's pose.
bool addSdfVisuals(const sdf::Link& sdf_link, const std::vector<std::string>& model_path,
                   LinkDescription* link, std::string* error);

}  // namespace core
}  // namespace onedof_sim
