// The simulator node with one more model plugin than the registry's: libonedof_sim_hook_probe.so,
// which tells every call of its hooks on <robotNamespace>/hook_probe (std_msgs/String:
// "before|after TIME_NS STEP", "reset"), so that a test over real ROS sees what the seam calls,
// in which order and at which sim time, and that the plugin is gone after delete_model.
#include <string>
#include <vector>

#include <ros/ros.h>
#include <std_msgs/String.h>

#include "node_main.h"
#include "plugins/model_plugin.h"
#include "plugins/registry.h"

namespace {

using onedof_sim::World;
using namespace onedof_sim::plugins;

class HookProbe : public ModelPlugin {
 public:
  explicit HookProbe(const ModelPluginContext& context)
      : publisher_(ros::NodeHandle(context.node).advertise<std_msgs::String>("hook_probe", 100000)) {}

  void beforeStep(World&, const StepTime& at) override { tell("before", at); }
  void afterStep(World&, const StepTime& at) override { tell("after", at); }
  void reset(World&) override { told_.push_back("reset"); }

  std::vector<Publication> takePublications() override {
    std::vector<Publication> publications;
    for (const std::string& text : told_) {
      publications.push_back([this, text] {
        std_msgs::String message;
        message.data = text;
        publisher_.publish(message);
      });
    }
    told_.clear();
    return publications;
  }

 private:
  void tell(const char* hook, const StepTime& at) {
    told_.push_back(std::string(hook) + " " + std::to_string(at.time_ns) + " " +
                    std::to_string(at.step));
  }

  ros::Publisher publisher_;
  std::vector<std::string> told_;
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<ModelPluginType> types = modelPluginRegistry();
  types.push_back({"libonedof_sim_hook_probe.so",
                   [](const ModelPluginContext& context, std::string*) {
                     return std::unique_ptr<ModelPlugin>(new HookProbe(context));
                   }});
  return runSimulatorNode(argc, argv, std::move(types));
}
