#include "lockstep.h"

namespace onedof_sim {

Lockstep::Lockstep(const Options& options) : options_(options) {}

bool Lockstep::heard(const std::string& joint, const std::string& caller, bool until_cleared,
                     int64_t now_ns) {
  if (!options_.enabled || until_cleared) return false;
  const bool waits = now_ns > 0;
  auto found = joints_.find(joint);
  if (found == joints_.end()) {
    joints_[joint] = {caller, waits};
    return waits;
  }
  Joint& known = found->second;
  const bool joined = waits && !known.waited_for;
  known.caller = caller;
  known.waited_for = waits;
  return joined;
}

std::vector<Lockstep::Awaited> Lockstep::awaited(const World& world, int64_t t_ns) const {
  std::vector<Awaited> out;
  JointInfo unused;
  for (const auto& [name, joint] : joints_) {
    // Checked after every step: the cheap question first. A joint of no model in the world
    // (not spawned yet, or deleted) holds nothing up.
    if (!joint.waited_for || world.jointEffortActive(name, t_ns)) continue;
    if (world.jointInfo(name, &unused).ok()) out.push_back({name, joint.caller});
  }
  return out;
}

bool Lockstep::holding() const {
  for (const auto& entry : joints_)
    if (entry.second.waited_for) return true;
  return false;
}

void Lockstep::giveUp(const std::vector<Awaited>& joints) {
  for (const Awaited& awaited : joints) {
    auto found = joints_.find(awaited.joint);
    if (found != joints_.end()) found->second.waited_for = false;
  }
}

}  // namespace onedof_sim
