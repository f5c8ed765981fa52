// The one list of model plugins: each is one file in this folder and one entry here, keyed by
// the filename a URDF's <gazebo><plugin> or an SDF's <plugin> names, as Gazebo loads it.
#include "registry.h"

namespace onedof_sim::plugins {

std::unique_ptr<ModelPlugin> makeGazeboRosControl(const ModelPluginContext&, std::string*);

const std::vector<ModelPluginType>& modelPluginRegistry() {
  static const std::vector<ModelPluginType> entries{
      {"libgazebo_ros_control.so", makeGazeboRosControl},
  };
  return entries;
}

}  // namespace onedof_sim::plugins
