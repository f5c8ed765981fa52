// Containing an engine that fails inside a call (EngineFault: an assertion inside ODE on input the
// world's checks let through): the failed engine is dropped and a new one built from the world's
// own records, every model at its state from before the call, so that the world goes on. A step
// is first taken again that way with the engine's fallback solver; only when that fails too is
// a model taken out, and only one the failed step involves.
#include <string>

#include "world_impl.h"

namespace onedof_sim {

using namespace core;

void World::Impl::rebuildEngine(const std::vector<BodyState>& states) {
  // Each model's bodies' states, taken while its old engine model still identifies them.
  std::vector<std::vector<BodyState>> model_states(models.size());
  for (size_t i = 0; i < models.size(); ++i) {
    model_states[i].resize(models[i]->bodies.size());
    for (const BodyState& s : states)
      if (s.model == models[i]->engine_model.get()) model_states[i][s.body] = s;
  }
  saved_states.clear();
  for (const auto& model : models) model->engine_model.reset();  // before the engine they live in
  contacts_current = false;
  engine = findEngine(engine_name).make();
  engine->setParams(params);
  for (size_t i = 0; i < models.size(); ++i) {
    ModelRecord* model = models[i].get();
    ModelSpec spec = model->spec;
    spec.bodies = model->bodies;
    model->engine_model = engine->addModel(spec);
    // The links where the bodies were; placeModel attaches the joints so that they read the
    // positions the world kept for them, then the bodies take their exact states back.
    std::vector<Pose> link_poses;
    for (const LinkRecord& link : model->links)
      link_poses.push_back(link.body >= 0 ? compose(model_states[i][link.body].pose, link.link_in_body)
                                          : link.anchored_pose);
    const bool velocity_capped = model->velocity_capped, blown_up = model->blown_up;
    placeModel(model, model->frame_pose, link_poses, currentPositions(*model));
    for (size_t body = 0; body < model->bodies.size(); ++body)
      model->engine_model->setBodyState(static_cast<int>(body), model_states[i][body].pose,
                                        model_states[i][body].twist);
    for (JointRecord& joint : model->joints)
      if (joint.engine_joint >= 0)
        joint.last_raw = model->engine_model->jointPosition(joint.engine_joint);
    model->velocity_capped = velocity_capped;
    model->blown_up = blown_up;
  }
}

std::vector<size_t> World::Impl::faultedModels() const {
  std::vector<size_t> found;
  for (size_t i = 0; i < models.size(); ++i)
    if (isBlownUp(*models[i])) found.push_back(i);
  if (!found.empty()) return found;
  const std::vector<BodyRef> touching = engine->contactBodies();
  for (size_t i = 0; i < models.size(); ++i)
    for (const BodyRef& body : touching)
      if (body.model == models[i]->engine_model.get()) {
        found.push_back(i);
        break;
      }
  return found;
}

Status World::Impl::stepContained() {
  std::string fault;
  bool retake = false, removed = false;
  for (;;) {
    try {
      stepEngine(retake);
      break;
    } catch (const EngineFault& error) {
      if (models.empty()) throw;  // nothing to take out
      const std::vector<BodyState> states = saved_states;
      if (!retake && engine->retakesFailedSteps(params)) {
        // The step once more from where it started, on a new engine, the way the engine takes
        // a step its solver failed: usually that step passes, and no model is lost.
        if (fault.empty()) fault = error.what();
        rebuildEngine(states);
        saveStates();
        retake = true;
        continue;
      }
      if (fault.empty()) fault = error.what();
      // Only a model the failed step involves is taken out: one it left non-finite, or the one
      // model in its contacts. With several in touch the engine cannot tell which made it fail,
      // and the world stops where the step started rather than lose a model that did not.
      const std::vector<size_t> culprits = faultedModels();
      const bool blown_up = !culprits.empty() && isBlownUp(*models[culprits.front()]);
      if (culprits.empty() || (!blown_up && culprits.size() > 1)) {
        std::string involved;
        for (size_t i : culprits) involved += (involved.empty() ? "'" : ", '") + models[i]->name + "'";
        rebuildEngine(states);
        saveStates();
        return {StatusCode::EngineFaultUnattributed,
                involved.empty() ? error.what()
                                 : std::string(error.what()) + "; models in touch: " + involved};
      }
      for (auto i = culprits.rbegin(); i != culprits.rend(); ++i) {
        warn("model '" + models[*i]->name + "' made the physics engine fail inside a step (" +
             error.what() + (retake ? ", with its fallback solver too" : "") +
             "): it was removed from the world, and the step taken again from where it started "
             "without it");
        destroyModel(*i);
      }
      removed = true;
      rebuildEngine(states);
      saveStates();
      retake = false;
    }
  }
  if (fault.empty()) return {};
  if (removed) return {StatusCode::EngineFault, fault};
  // Retaken: warned at most once a second of sim time, as a step can fail again and again.
  if (last_retake_warning_ns < 0 || time_ns < last_retake_warning_ns ||
      time_ns - last_retake_warning_ns >= 1000000000) {
    warn("the physics engine failed inside a step (" + fault + "): the step was taken again " +
         "from where it started with its fallback solver, every model kept");
    last_retake_warning_ns = time_ns;
  }
  return {};
}

}  // namespace onedof_sim
