// rosrun onedof_sim onedof_sim: the simulator node, with the registry's model plugins.
#include "node_main.h"
#include "plugins/registry.h"

int main(int argc, char** argv) {
  return runSimulatorNode(argc, argv, onedof_sim::plugins::modelPluginRegistry());
}
