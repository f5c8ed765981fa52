// The one list of model plugins, by Gazebo's filename.
#pragma once

#include <vector>

#include "model_plugin.h"

namespace onedof_sim::plugins {

const std::vector<ModelPluginType>& modelPluginRegistry();

}  // namespace onedof_sim::plugins
