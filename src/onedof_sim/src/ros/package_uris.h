// package:// URIs of a URDF, resolved as gazebo_ros resolves them before Gazebo reads the model.
#pragma once

#include <string>

namespace onedof_sim {

// Replaces each `package://PKG` in xml by PKG's folder (ros::package::getPath), as gazebo_ros'
// spawn_urdf_model does, so that `package://PKG/meshes/x.stl` names the file. False, with
// *missing the package's name, when a package is not found; the xml is then partly replaced.
// A `package://` with no `/` after the name is left as it is (gazebo_ros stops there too), and
// so is one whose name is no package name (letters, digits, `_`, `-`, `.`: prose in a comment),
// which gazebo_ros would look up and refuse. One whose path leaves the package's folder once
// normalised (`package://PKG/../../x`) is left as it is too: the core confines a package:// path
// to the model path, where it names no file, and the caller learns nothing of what is outside.
bool resolvePackageUris(std::string* xml, std::string* missing);

}  // namespace onedof_sim
