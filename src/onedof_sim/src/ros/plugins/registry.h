// The one list of model plugins and the one list of sensor plugins, by Gazebo's filename.
#pragma once

#include <vector>

#include "model_plugin.h"
#include "sensor_plugin.h"

namespace onedof_sim::plugins {

const std::vector<ModelPluginType>& modelPluginRegistry();
const std::vector<SensorPluginType>& sensorPluginRegistry();

}  // namespace onedof_sim::plugins
