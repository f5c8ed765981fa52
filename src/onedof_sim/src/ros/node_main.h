// The simulator node's main, with the model plugins spawned models may name (main.cpp passes
// the registry; a test node passes the registry and a probe of its own).
#pragma once

#include <vector>

#include "plugins/model_plugin.h"

int runSimulatorNode(int argc, char** argv,
                     std::vector<onedof_sim::plugins::ModelPluginType> plugin_types);
