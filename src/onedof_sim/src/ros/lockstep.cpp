#include "lockstep.h"

#include <algorithm>
#include <utility>

namespace onedof_sim {

Lockstep::Lockstep(const Options& options) : options_(options) {}

bool Lockstep::heard(const std::string& joint, const std::string& caller, bool until_cleared,
                     int64_t now_ns, int64_t duration_ns) {
  if (!options_.enabled || until_cleared) return false;
  const bool waits = now_ns > 0;
  auto found = joints_.find(joint);
  if (found == joints_.end()) {
    joints_[joint] = {caller, waits, duration_ns};
    return waits;
  }
  Joint& known = found->second;
  const bool joined = waits && !known.waited_for;
  known.caller = caller;
  known.waited_for = waits;
  known.period_ns = duration_ns;
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

bool Lockstep::running(const World& world, int64_t t_ns) const {
  for (const auto& [name, joint] : joints_)
    if (joint.waited_for && world.jointEffortActive(name, t_ns)) return true;
  return false;
}

std::optional<int64_t> Lockstep::wakeTime(const World& world, int64_t t_ns) const {
  std::optional<int64_t> period;
  JointInfo unused;
  for (const auto& [name, joint] : joints_) {
    if (!joint.waited_for || !world.jointInfo(name, &unused).ok()) continue;
    if (world.jointEffortActive(name, t_ns) || joint.period_ns <= 0) return std::nullopt;
    period = std::min(period.value_or(joint.period_ns), joint.period_ns);
  }
  if (!period) return std::nullopt;
  return t_ns + *period;
}

Lockstep::Clock::time_point Lockstep::lastRequest(const std::vector<Awaited>& joints) const {
  Clock::time_point latest;
  for (const Awaited& awaited : joints) {
    auto found = callers_.find(awaited.caller);
    if (found != callers_.end()) latest = std::max(latest, found->second.last_request);
  }
  return latest;
}

void Lockstep::commandedFrom(const std::string& caller, std::optional<int> pid, ProcessRuns runs) {
  Caller& known = callers_[caller];
  known.pid = pid;
  known.runs_at_command = std::move(runs);
}

template <class F>
void Lockstep::forEachWaitedFor(const World& world, F&& f) const {
  JointInfo unused;
  for (const auto& [name, joint] : joints_) {
    if (!joint.waited_for || !world.jointInfo(name, &unused).ok()) continue;
    auto found = callers_.find(joint.caller);
    f(joint.caller, found == callers_.end() ? nullptr : &found->second);
  }
}

std::vector<Lockstep::Watched> Lockstep::watched(const World& world) const {
  std::vector<Watched> out;
  forEachWaitedFor(world, [&](const std::string& name, const Caller* caller) {
    if (!caller || !caller->pid) return;
    for (const Watched& known : out)
      if (known.pid == *caller->pid) return;
    out.push_back({name, *caller->pid, caller->runs_at_command});
  });
  return out;
}

bool Lockstep::someUnwatched(const World& world) const {
  bool unwatched = false;
  forEachWaitedFor(world, [&](const std::string&, const Caller* caller) {
    if (!caller || !caller->pid) unwatched = true;
  });
  return unwatched;
}

std::optional<int> Lockstep::pidOf(const std::string& caller) const {
  auto found = callers_.find(caller);
  return found == callers_.end() ? std::nullopt : found->second.pid;
}

void Lockstep::giveUp(const std::vector<Awaited>& joints) {
  for (const Awaited& awaited : joints) {
    auto found = joints_.find(awaited.joint);
    if (found != joints_.end()) found->second.waited_for = false;
  }
}

}  // namespace onedof_sim
