// The world file the node is started with (gzserver's WORLD_FILE, empty_world.launch's
// world_name): found as gzserver finds it, read by the core (onedof_sim/world_file.h), and worded
// for the log when it cannot be loaded or holds what the simulator does not simulate.
#pragma once

#include <string>
#include <vector>

#include <onedof_sim/world.h>
#include <onedof_sim/world_file.h>

namespace onedof_sim {

// Reads the world file `given` (a path; a relative one is looked up as gzserver does: from the
// current folder, then in this package's folder, which has Gazebo's worlds/empty.world, then in
// each folder of GAZEBO_RESOURCE_PATH) with model:// in model_path. On success fills *out and logs
// what the world holds that is not simulated (lights, plugins, scene, ...), each once; else sets
// *error to why, naming the file.
bool loadWorldFile(const std::string& given, const std::vector<std::string>& model_path,
                   const PhysicsParams& base, WorldFile* out, std::string* error);

}  // namespace onedof_sim
