#include "controller_set.h"

#include <algorithm>
#include <tuple>
#include <utility>

namespace onedof_sim::control {

namespace {

template <typename T>
bool contains(const std::vector<T>& list, const T& item) {
  return std::find(list.begin(), list.end(), item) != list.end();
}

}  // namespace

const char* controllerStateName(ControllerState state) {
  switch (state) {
    case ControllerState::Initialized: return "initialized";
    case ControllerState::Running: return "running";
    case ControllerState::Stopped: return "stopped";
  }
  return "unknown";
}

ControllerSet::Loaded* ControllerSet::find(const std::string& name) {
  for (Loaded& loaded : loaded_)
    if (loaded.name == name) return &loaded;
  return nullptr;
}

const ControllerSet::Loaded* ControllerSet::find(const std::string& name) const {
  return const_cast<ControllerSet*>(this)->find(name);
}

LoadResult ControllerSet::prepareLoad(const std::string& name, const ParamSource& params,
                                      const std::string& ns) const {
  LoadResult result;
  if (!params.getString(ns + "/type", &result.type)) {
    result.outcome = LoadOutcome::NoType;
    return result;
  }
  const ControllerType* type = findControllerType(result.type, types_);
  if (!type) {
    result.outcome = LoadOutcome::UnknownType;
    return result;
  }
  if (find(name)) {
    result.outcome = LoadOutcome::AlreadyLoaded;
    return result;
  }
  result.controller = type->make(robot_, params, ns, &result.error);
  result.outcome = result.controller ? LoadOutcome::Loaded : LoadOutcome::InitFailed;
  return result;
}

LoadOutcome ControllerSet::commitLoad(const std::string& name, LoadResult prepared) {
  if (prepared.outcome != LoadOutcome::Loaded) return prepared.outcome;
  if (find(name)) return LoadOutcome::AlreadyLoaded;
  loaded_.push_back(
      {name, prepared.type, ControllerState::Initialized, std::move(prepared.controller)});
  return LoadOutcome::Loaded;
}

LoadResult ControllerSet::load(const std::string& name, const ParamSource& params,
                               const std::string& ns) {
  LoadResult result = prepareLoad(name, params, ns);
  result.outcome = commitLoad(name, result);
  if (result.outcome != LoadOutcome::Loaded) result.controller.reset();
  return result;
}

UnloadOutcome ControllerSet::unload(const std::string& name,
                                    std::shared_ptr<Controller>* unloaded) {
  Loaded* loaded = find(name);
  if (!loaded) return UnloadOutcome::NotLoaded;
  if (loaded->state == ControllerState::Running) return UnloadOutcome::StillRunning;
  if (unloaded) *unloaded = std::move(loaded->controller);
  loaded_.erase(loaded_.begin() + (loaded - loaded_.data()));
  return UnloadOutcome::Unloaded;
}

SwitchResult ControllerSet::switchControllers(const std::vector<std::string>& start,
                                              const std::vector<std::string>& stop,
                                              Strictness strictness, int64_t time_ns) {
  const bool strict = strictness == Strictness::Strict;
  SwitchResult result;
  // The requests, in the order asked; a name asked twice once.
  std::vector<Loaded*> to_stop, to_start;
  for (const auto& [names, requests, unknown] :
       {std::make_tuple(&stop, &to_stop, SwitchOutcome::UnknownToStop),
        std::make_tuple(&start, &to_start, SwitchOutcome::UnknownToStart)}) {
    for (const std::string& name : *names) {
      Loaded* loaded = find(name);
      if (!loaded) {
        if (!strict) continue;
        result.outcome = unknown;
        result.controller = name;
        return result;
      }
      if (!contains(*requests, loaded)) requests->push_back(loaded);
    }
  }
  // Requests that would change nothing: refused (STRICT) or dropped (BEST_EFFORT).
  auto drop = [](std::vector<Loaded*>* requests, Loaded* loaded) {
    requests->erase(std::remove(requests->begin(), requests->end(), loaded), requests->end());
  };
  for (Loaded& loaded : loaded_) {
    const bool running = loaded.state == ControllerState::Running;
    const bool in_stop = contains(to_stop, &loaded);
    if (!running && in_stop) {
      if (strict) {
        result.outcome = SwitchOutcome::NotRunning;
        result.controller = loaded.name;
        return result;
      }
      drop(&to_stop, &loaded);
    }
    if (running && !in_stop && contains(to_start, &loaded)) {
      if (strict) {
        result.outcome = SwitchOutcome::AlreadyRunning;
        result.controller = loaded.name;
        return result;
      }
      drop(&to_start, &loaded);
    }
  }
  // No joint claimed by two controllers that would run.
  std::vector<std::string> claimed;
  for (Loaded& loaded : loaded_) {
    const bool will_run = contains(to_start, &loaded) ||
                          (loaded.state == ControllerState::Running && !contains(to_stop, &loaded));
    if (!will_run) continue;
    for (const std::string& joint : loaded.controller->claims().resources) {
      if (contains(claimed, joint)) {
        result.outcome = SwitchOutcome::ResourceConflict;
        result.resource = joint;
        return result;
      }
      claimed.push_back(joint);
    }
  }
  for (Loaded* loaded : to_stop) {
    loaded->controller->stopping(time_ns);
    loaded->state = ControllerState::Stopped;
  }
  for (Loaded* loaded : to_start) {
    loaded->controller->starting(time_ns);
    loaded->state = ControllerState::Running;
  }
  return result;
}

void ControllerSet::update(int64_t time_ns, int64_t period_ns, bool reset_controllers) {
  last_update_ns_ = time_ns;
  for (Loaded& loaded : loaded_) {
    if (loaded.state != ControllerState::Running) continue;
    if (reset_controllers) {
      loaded.controller->stopping(time_ns);
      loaded.controller->starting(time_ns);
    }
    loaded.controller->update(time_ns, period_ns);
  }
}

std::vector<ControllerInfo> ControllerSet::list() const {
  std::vector<ControllerInfo> infos;
  for (const Loaded& loaded : loaded_)
    infos.push_back({loaded.name, loaded.type, loaded.state, loaded.controller->claims()});
  return infos;
}

std::vector<std::shared_ptr<Controller>> ControllerSet::unloadAll(int64_t time_ns) {
  std::vector<std::shared_ptr<Controller>> unloaded;
  for (Loaded& loaded : loaded_) {
    if (loaded.state == ControllerState::Running) loaded.controller->stopping(time_ns);
    unloaded.push_back(std::move(loaded.controller));
  }
  loaded_.clear();
  return unloaded;
}

}  // namespace onedof_sim::control
