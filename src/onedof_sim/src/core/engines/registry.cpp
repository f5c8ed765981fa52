// The one list of physics engines. The node (~physics, physics:=), the launch files, the tests,
// the benchmark, the tutorial player and the cross-validation all read it (the node prints it:
// `rosrun onedof_sim onedof_sim --list-physics`). The first entry is the default.
#include "engine.h"

namespace onedof_sim {
namespace core {

std::unique_ptr<Engine> makeOdeEngine();
std::unique_ptr<Engine> makeBulletEngine();
std::unique_ptr<Engine> makeDartEngine();
std::unique_ptr<Engine> makeMujocoEngine();

const std::vector<EngineEntry>& engineRegistry() {
  static const std::vector<EngineEntry> entries{
      {"ode", makeOdeEngine},
      {"bullet", makeBulletEngine},
      {"dart", makeDartEngine},
      {"mujoco", makeMujocoEngine},
  };
  return entries;
}

}  // namespace core
}  // namespace onedof_sim
