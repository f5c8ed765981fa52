// World's lifecycle: the engine and its parameters, spawning and deleting models, reset, and the
// step (jobs and damping applied, the engine stepped with its non-finite rollback, speeds capped,
// joint positions and time advanced). See world_impl.h for the frames and the other parts.
#include "onedof_sim/world.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "onedof_sim/world_file.h"
#include "world_impl.h"

namespace onedof_sim {

using namespace core;

namespace {

std::string formatNumber(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

size_t countMovingJoints(const ModelRecord& model) {
  return std::count_if(model.joints.begin(), model.joints.end(),
                       [](const JointRecord& joint) { return joint.engine_joint >= 0; });
}

}  // namespace

namespace core {

const EngineEntry& findEngine(const std::string& name) {
  for (const EngineEntry& entry : engineRegistry())
    if (entry.name == name) return entry;
  std::string known;
  for (const EngineEntry& entry : engineRegistry()) known += (known.empty() ? "" : ", ") + entry.name;
  throw std::invalid_argument("unknown physics engine '" + name + "' (known: " + known + ")");
}

}  // namespace core

World::Impl::Impl(const std::string& name, const PhysicsParams& p)
    : engine_name(name), engine(findEngine(name).make()) {
  engine->reseed();
  // A constructor cannot report: invalid parameters fall back to the defaults.
  applyParams(validateParams(p).ok() ? p : PhysicsParams());
}

World::Impl::~Impl() {
  models.clear();  // before the engine they live in
}

void World::Impl::applyParams(const PhysicsParams& p) {
  params = p;
  step_ns = std::llround(p.step * 1e9);
  engine->setParams(p);
}

void World::Impl::warn(const std::string& text) {
  if (warnings.size() < kMaxWarnings) warnings.push_back(text);
}

void World::Impl::destroyModel(size_t index) {
  ModelRecord* model = models[index].get();
  dropJobs([model](const ModelRecord* m) { return m == model; });
  models.erase(models.begin() + index);
  contacts_current = false;
}

// --- stepping --------------------------------------------------------------------------------

void World::Impl::saveStates() {
  saved_states.clear();
  for (const auto& model : models)
    for (size_t body = 0; body < model->bodies.size(); ++body) {
      const int b = static_cast<int>(body);
      saved_states.push_back({model->engine_model.get(), b, model->engine_model->bodyPose(b),
                              model->engine_model->bodyTwist(b)});
    }
}

bool World::Impl::isBlownUp(const ModelRecord& model) const {
  for (size_t body = 0; body < model.bodies.size(); ++body) {
    const int b = static_cast<int>(body);
    if (!isFinite(model.engine_model->bodyPose(b)) || !isFinite(model.engine_model->bodyTwist(b)))
      return true;
  }
  return false;
}

void World::Impl::stepEngine(bool retake) {
  std::string solver_message;
  applyDamping(applyJobs(time_ns));
  applyMotors();
  engine->step(params.step, &solver_message, retake);
  std::vector<ModelRecord*> newly_blown;
  for (const auto& model : models)
    if (!model->blown_up && isBlownUp(*model)) newly_blown.push_back(model.get());
  if (!newly_blown.empty()) {
    for (const BodyState& s : saved_states) s.model->setBodyState(s.body, s.pose, s.twist);
    for (ModelRecord* model : newly_blown) {
      model->blown_up = true;
      holdAtSavedState(*model);
    }
    releaseMotors();
    applyDamping(applyJobs(time_ns));
    applyMotors();
    engine->step(params.step, &solver_message, retake);
  }
  releaseMotors();
  contacts_current = true;
  if (!solver_message.empty() && !engine_struggled) warn(solver_message);
  engine_struggled = !solver_message.empty();
  for (const auto& model : models) {
    const bool blown = isBlownUp(*model);
    if (blown) holdAtSavedState(*model);
    const bool stopped =
        blown || std::count(newly_blown.begin(), newly_blown.end(), model.get()) > 0;
    if (stopped && (model->last_blow_up_warning_ns < 0 ||
                    time_ns - model->last_blow_up_warning_ns >= 1000000000)) {
      warn("model '" + model->name +
           "' reached a non-finite state: it was stopped where the step started while the "
           "rest of the world ran on");
      model->last_blow_up_warning_ns = time_ns;
    }
    model->blown_up = blown;
  }
}

void World::Impl::holdAtSavedState(const ModelRecord& model) {
  for (const BodyState& s : saved_states)
    if (s.model == model.engine_model.get()) s.model->setBodyState(s.body, s.pose, Twist());
}

void World::Impl::guardStates() {
  const double max_angular = maxAngularSpeed(params.step);
  for (const auto& model : models) {
    EngineModel& engine_model = *model->engine_model;
    const int body_count = static_cast<int>(model->bodies.size());
    double scale = 1;
    for (int body = 0; body < body_count; ++body) {
      const Twist twist = engine_model.bodyTwist(body);
      const double linear = norm(twist.linear);
      const double angular = norm(twist.angular);
      if (linear > kMaxLinearSpeed) scale = std::min(scale, kMaxLinearSpeed / linear);
      if (angular > max_angular) scale = std::min(scale, max_angular / angular);
    }
    if (scale < 1) {
      for (int body = 0; body < body_count; ++body) {
        const Twist twist = engine_model.bodyTwist(body);
        engine_model.setBodyState(body, engine_model.bodyPose(body),
                                  {scale * twist.linear, scale * twist.angular});
      }
      if (!model->velocity_capped)
        warn("model '" + model->name + "' exceeded " + formatNumber(kMaxLinearSpeed) +
             " m/s or " + formatNumber(max_angular) + " rad/s: its speed is being capped");
    }
    model->velocity_capped = scale < 1;
  }
}

Status World::Impl::step() {
  if (time_ns > kEndOfTimeNs - step_ns) {
    if (!time_ended)
      warn("sim time reached the end of ROS time (2^32 s): the world stands still until "
           "reset_simulation");
    time_ended = true;
    return {};
  }
  saveStates();
  const Status status = stepContained();
  if (status.code == StatusCode::EngineFaultUnattributed) {  // the world stands where it was
    joint_commands.clear();
    joint_motors.clear();
    return status;
  }
  guardStates();
  for (const auto& model : models) updateJointPositions(model.get());
  time_ns += step_ns;
  ++steps;
  dropExpiredJobs(time_ns);
  joint_commands.clear();
  joint_motors.clear();
  return status;
}

std::vector<std::string> World::engineNames() {
  std::vector<std::string> names;
  for (const EngineEntry& entry : engineRegistry()) names.push_back(entry.name);
  return names;
}

World::World(const std::string& engine, const PhysicsParams& params)
    : impl_(new Impl(engine, params)) {}
World::~World() = default;

Status World::step() { return impl_->step(); }
int64_t World::timeNs() const { return impl_->time_ns; }
double World::time() const { return impl_->time_ns * 1e-9; }
uint64_t World::stepCount() const { return impl_->steps; }

Status World::setClock(int64_t time_ns, uint64_t step_count) {
  if (time_ns < 0 || time_ns > kEndOfTimeNs) return outOfRange("sim_time", 0, kEndOfTimeNs * 1e-9);
  impl_->time_ns = time_ns;
  impl_->steps = step_count;
  impl_->time_ended = false;
  return {};
}
const std::string& World::engineName() const { return impl_->engine_name; }
const PhysicsParams& World::params() const { return impl_->params; }

Status World::setParams(const PhysicsParams& params) {
  Status status = validateParams(params);
  if (!status.ok()) return status;
  if (impl_->engine->exactSolver(params))
    for (const auto& model : impl_->models)
      if (model->engine_model && countMovingJoints(*model) > kMaxExactSolverJoints) {
        status = {StatusCode::InvalidParameter, "quick_step"};
        status.max = kMaxExactSolverJoints;
        return status;
      }
  impl_->applyParams(params);
  return status;
}

std::vector<std::string> World::takeWarnings() {
  std::vector<std::string> warnings;
  warnings.swap(impl_->warnings);
  return warnings;
}

PreparedModel::PreparedModel() : content_(std::make_unique<Content>()) {}
PreparedModel::~PreparedModel() = default;
PreparedModel::PreparedModel(PreparedModel&&) noexcept = default;
PreparedModel& PreparedModel::operator=(PreparedModel&&) noexcept = default;
const Status& PreparedModel::status() const { return content_->status; }
const std::vector<InertiaWarning>& PreparedModel::warnings() const { return content_->warnings; }
const std::vector<std::string>& PreparedModel::leftOut() const { return content_->left_out; }

Status World::spawn(const std::string& name, const std::string& xml, ModelFormat format,
                    const Pose& pose, const std::string& reference_frame) {
  const Status admissible = checkSpawn(name, pose, reference_frame);
  if (!admissible.ok()) return admissible;
  return spawn(name, prepare(xml, format, impl_->model_path), pose, reference_frame);
}

Status World::checkSpawn(const std::string& name, const Pose& pose,
                         const std::string& reference_frame) const {
  Status status = checkPose(pose);
  if (!status.ok()) return status;
  if (name.empty()) return {StatusCode::EmptyModelName, {}};
  // Scoped names ("model::link") and reference frames must say one thing: a model called
  // "robot::link2" would take over robot's link2 as a frame, one called "world" the world.
  if (name.find("::") != std::string::npos || name == kWorldLink)
    return {StatusCode::InvalidModelName, name};
  if (impl_->findModel(name)) return {StatusCode::ModelExists, name};
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  return {};
}

PreparedModel World::prepare(const std::string& xml, ModelFormat format,
                             const std::vector<std::string>& model_path) {
  PreparedModel prepared;
  PreparedModel::Content& content = *prepared.content_;
  content.status = precheckModelXml(xml, format);
  if (!content.status.ok()) return prepared;
  ModelDescription desc;
  content.status = format == ModelFormat::Urdf ? parseUrdf(xml, model_path, &desc)
                                               : parseSdf(xml, model_path, &desc);
  if (content.status.ok()) plan(desc, &prepared);
  return prepared;
}

PreparedModel World::prepare(const WorldFileModel& model) {
  PreparedModel prepared;
  prepared.content_->status = model.read;
  if (model.read.ok()) plan(*model.description, &prepared);
  return prepared;
}

void World::plan(const ModelDescription& desc, PreparedModel* prepared) {
  PreparedModel::Content& content = *prepared->content_;
  if (!isFinite(desc.pose) || !withinPosition(desc.pose.position)) {
    std::ostringstream why;
    why << "the model's own <pose> is not finite or lies beyond " << kMaxPosition << " m";
    content.status = rejected(why.str());
    return;
  }
  content.left_out = desc.left_out;
  content.record.is_static = desc.is_static;
  content.model_pose = desc.pose;
  content.status = planModel(desc, &content.record, &content.spec, &content.warnings);
}

Status World::spawn(const std::string& name, PreparedModel prepared, const Pose& pose,
                    const std::string& reference_frame) {
  Status status = checkSpawn(name, pose, reference_frame);
  if (!status.ok()) return status;
  PreparedModel::Content& content = *prepared.content_;
  if (!content.status.ok()) return content.status;
  const size_t moving_joints = content.spec.joints.size();
  if (impl_->engine->exactSolver(impl_->params) && moving_joints > kMaxExactSolverJoints)
    return rejected(
        "the model has " + std::to_string(moving_joints) + " moving joints; at most " +
        std::to_string(kMaxExactSolverJoints) +
        " are accepted with the exact solver (ODE's dWorldStep, quick_step false), whose step "
        "cost grows as joints^2.8 (" + std::to_string(kMaxExactSolverJoints) +
        ": about 1 ms a step); with quick_step (the node's ~quick_step: dWorldQuickStep, cost "
        "linear in the joints) it is accepted");
  Pose frame;
  Twist unused;
  impl_->resolveFrame(reference_frame, &frame, &unused);
  // As gazebo_ros' spawn services: the model's own pose taken in the requested one.
  const Pose spawn_pose =
      compose(compose(frame, {pose.position, normalized(pose.orientation)}), content.model_pose);
  if (!withinPosition(spawn_pose.position))
    return outOfRange("pose.position", -kMaxPosition, kMaxPosition);
  auto model = std::make_unique<ModelRecord>(std::move(content.record));
  model->name = name;
  model->spec = std::move(content.spec);
  model->spawn_pose = spawn_pose;
  try {
    model->engine_model = impl_->engine->addModel(model->spec);
    impl_->resetModel(model.get());
  } catch (const EngineFault& fault) {
    // The other models' states are as they were: read them from the failed engine.
    model.reset();
    impl_->saveStates();
    impl_->rebuildEngine(impl_->saved_states);
    impl_->warn("spawning model '" + name + "' failed inside the physics engine (" + fault.what() +
                "): it was refused and the engine rebuilt with every other model where it was");
    return {StatusCode::EngineFault, fault.what()};
  }
  impl_->models.push_back(std::move(model));
  return {};
}

const std::vector<std::string>& World::modelPath() const { return impl_->model_path; }

void World::setModelPath(const std::vector<std::string>& folders) {
  // libsdformat would try a relative folder against its own install first.
  impl_->model_path.clear();
  for (const std::string& folder : folders)
    if (!folder.empty())
      impl_->model_path.push_back(std::filesystem::absolute(folder).lexically_normal().string());
}

Status World::deleteModel(const std::string& name) {
  for (size_t i = 0; i < impl_->models.size(); ++i)
    if (impl_->models[i]->name == name) {
      impl_->destroyModel(i);
      return {};
    }
  return {StatusCode::ModelNotFound, name};
}

std::vector<std::string> World::modelNames() const {
  std::vector<std::string> names;
  for (const auto& model : impl_->models) names.push_back(model->name);
  return names;
}

void World::resetWorld() {
  for (const auto& model : impl_->models) impl_->resetModel(model.get());
  impl_->dropJobs([](const ModelRecord*) { return true; });
}

Status World::resetModel(const std::string& name) {
  ModelRecord* model = impl_->findModel(name);
  if (!model) return {StatusCode::ModelNotFound, name};
  impl_->resetModel(model);
  impl_->dropJobs([model](const ModelRecord* m) { return m == model; });
  return {};
}

void World::resetSimulation() {
  resetWorld();
  if (!impl_->engine->repeatsWhenPutBack()) {
    impl_->saveStates();
    impl_->rebuildEngine(impl_->saved_states);
  }
  impl_->engine->reseed();
  impl_->time_ns = 0;
  impl_->time_ended = false;
  impl_->steps = 0;
}

}  // namespace onedof_sim
