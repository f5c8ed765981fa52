// Containing an engine that fails inside a call (EngineFault: an assertion inside ODE on input the
// world's checks let through): the failed engine is dropped and a new one built from the world's
// own records, every model at its state from before the call, so that the world goes on.
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
  engine = findEngine(engine_name).make();
  engine->addGroundPlane(kGroundMu, kGroundMu2);
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

Status World::Impl::stepContained() {
  std::string fault;
  for (;;) {
    try {
      stepEngine();
      break;
    } catch (const EngineFault& error) {
      if (models.empty()) throw;  // the ground alone: nothing to take out
      if (fault.empty()) fault = error.what();
      // The model that made the step fail: those the failed step left non-finite (a failed
      // engine can still be read), else the last spawned; the step is then tried again.
      std::vector<size_t> culprits;
      for (size_t i = 0; i < models.size(); ++i)
        if (isBlownUp(*models[i])) culprits.push_back(i);
      if (culprits.empty()) culprits.push_back(models.size() - 1);
      const std::vector<BodyState> states = saved_states;
      for (auto i = culprits.rbegin(); i != culprits.rend(); ++i) {
        warn("model '" + models[*i]->name + "' made the physics engine fail inside a step (" +
             error.what() + "): it was removed from the world, and the step taken again from " +
             "where it started without it");
        destroyModel(*i);
      }
      rebuildEngine(states);
      saveStates();
    }
  }
  if (fault.empty()) return {};
  return {StatusCode::EngineFault, fault};
}

}  // namespace onedof_sim
