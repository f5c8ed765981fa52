#include "gazebo_api.h"

#include <malloc.h>

#include <sstream>
#include <utility>

#include <tinyxml2.h>

#include "conversions.h"
#include "package_uris.h"
#include "plugins/model_plugins.h"
#include "plugins/registry.h"
#include "status_text.h"

namespace onedof_sim {
namespace {

// Which format model_xml is, from its root element; Gazebo accepts either on both spawn services.
// Else ModelRejected with the reason, as the world's parsers say it.
Status detectModelFormat(const std::string& xml, ModelFormat* format) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    const char* detail = doc.ErrorStr();
    return {StatusCode::ModelRejected,
            std::string("model_xml is not well-formed XML: ") + (detail ? detail : "parse error")};
  }
  const tinyxml2::XMLElement* root = doc.RootElement();
  const std::string root_name = root ? root->Name() : "";
  if (root_name == "robot") {
    *format = ModelFormat::Urdf;
  } else if (root_name == "sdf") {
    *format = ModelFormat::Sdf;
  } else {
    return {StatusCode::ModelRejected, "model_xml has root element <" + root_name +
                                           ">, expected <robot> (URDF) or <sdf> (SDF)"};
  }
  return {};
}

// The start-up line's note of the names beyond gazebo_ros' the node serves.
std::string extrasText(const NodeOptions& options) {
  std::vector<std::string> extras;
  if (options.enable_step_simulation) extras.push_back("step_simulation");
  if (options.enable_collision_markers) extras.push_back("the world view's markers");
  if (extras.empty()) return "";
  std::string text = " with ";
  for (size_t i = 0; i < extras.size(); ++i) text += (i ? " and " : "") + extras[i];
  return text + " (not Gazebo's)";
}

// The threads serving the global queue: while one parses a large model, the other serves the rest.
constexpr int kServiceThreads = 2;

// Gives the pages the heap holds free back to the system. glibc keeps what a model's parse, a
// refused spawn or a deleted model freed (in each service thread's arena), so the node's memory
// would stay at its largest model's peak for ever.
void releaseFreedMemory() { malloc_trim(0); }

}  // namespace

GazeboApi::GazeboApi(const NodeOptions& options,
                     std::vector<plugins::ModelPluginType> plugin_types)
    : loop_(options),
      plugin_types_(std::move(plugin_types)),
      private_nh_("~"),
      step_spinner_(1, &step_queue_) {
  if (options.world) spawnWorldModels(*options.world);
  if (options.enable_ros_network) advertiseServices(options.enable_step_simulation);
  step_spinner_.start();
  effort_thread_ = std::thread([this] {
    // callOne returns once the callback has run and roscpp has written its reply.
    while (!stopping_ && ros::ok())
      if (effort_queue_.callOne(ros::WallDuration(0.1)) == ros::CallbackQueue::Called)
        loop_.effortReplied();
  });
  for (int i = 0; i < kServiceThreads; ++i) {
    service_threads_.emplace_back([this] { serveGlobalQueue(); });
  }
  const PhysicsSettings physics = loop_.physics();
  const std::string api =
      options.enable_ros_network
          ? "serving the Gazebo API under " + private_nh_.getNamespace() + extrasText(options)
          : "ROS gazebo topics/services are disabled (enable_ros_network is false): /clock only" +
                std::string(options.enable_step_simulation || options.enable_collision_markers
                                ? " (~enable_step_simulation and ~enable_collision_markers "
                                  "serve nothing without it)"
                                : "");
  ROS_INFO("onedof_sim, standing in for Gazebo: %s (step %g s, max_update_rate %g Hz%s%s)",
           api.c_str(), physics.params.step, physics.max_update_rate,
           loop_.paused() ? ", paused" : "", options.lockstep.enabled ? ", lock-step" : "");
}

void GazeboApi::advertiseServices(bool step_simulation) {
  parameter_descriptions_pub_ = private_nh_.advertise<dynamic_reconfigure::ConfigDescription>(
      "parameter_descriptions", 1, true);
  parameter_updates_pub_ =
      private_nh_.advertise<dynamic_reconfigure::Config>("parameter_updates", 1, true);
  // The start-up settings are the defaults a client resets to.
  parameter_descriptions_pub_.publish(physicsDescription(loop_.physics()));
  parameter_updates_pub_.publish(toConfig(loop_.physics()));

  if (step_simulation) {
    ros::AdvertiseServiceOptions step_options;
    step_options.init<StepSimulation::Request, StepSimulation::Response>(
        "step_simulation", [this](StepSimulation::Request& req, StepSimulation::Response& res) {
          return stepSimulation(req, res);
        });
    step_options.callback_queue = &step_queue_;
    step_service_ = private_nh_.advertiseService(step_options);
  }
  // apply_joint_effort on a thread of its own, which tells the loop when each reply is written:
  // in lock-step a stop's clock waits for the commanding controller to have its reply (SimLoop).
  ros::AdvertiseServiceOptions effort_options;
  effort_options.initBySpecType<
      Event<gazebo_msgs::ApplyJointEffort::Request, gazebo_msgs::ApplyJointEffort::Response>>(
      "apply_joint_effort",
      [this](Event<gazebo_msgs::ApplyJointEffort::Request,
                   gazebo_msgs::ApplyJointEffort::Response>& event) {
        return applyJointEffort(event);
      });
  effort_options.callback_queue = &effort_queue_;
  effort_service_ = private_nh_.advertiseService(effort_options);
  auto& n = private_nh_;
  subscribers_ = {
      n.subscribe("set_model_state", 10, &GazeboApi::setModelStateTopic, this),
      n.subscribe("set_link_state", 10, &GazeboApi::setLinkStateTopic, this),
  };
  services_ = {
      n.advertiseService("get_joint_properties", &GazeboApi::getJointProperties, this),
      n.advertiseService("clear_joint_forces", &GazeboApi::clearJointForces, this),
      n.advertiseService("apply_body_wrench", &GazeboApi::applyBodyWrench, this),
      n.advertiseService("clear_body_wrenches", &GazeboApi::clearBodyWrenches, this),
      n.advertiseService("spawn_urdf_model", &GazeboApi::spawnUrdfModel, this),
      n.advertiseService("spawn_sdf_model", &GazeboApi::spawnSdfModel, this),
      n.advertiseService("delete_model", &GazeboApi::deleteModel, this),
      n.advertiseService("get_model_state", &GazeboApi::getModelState, this),
      n.advertiseService("set_model_state", &GazeboApi::setModelState, this),
      n.advertiseService("get_link_state", &GazeboApi::getLinkState, this),
      n.advertiseService("set_link_state", &GazeboApi::setLinkState, this),
      n.advertiseService("set_model_configuration", &GazeboApi::setModelConfiguration, this),
      n.advertiseService("get_model_properties", &GazeboApi::getModelProperties, this),
      n.advertiseService("get_world_properties", &GazeboApi::getWorldProperties, this),
      n.advertiseService("get_link_properties", &GazeboApi::getLinkProperties, this),
      n.advertiseService("set_link_properties", &GazeboApi::setLinkProperties, this),
      n.advertiseService("set_joint_properties", &GazeboApi::setJointProperties, this),
      n.advertiseService("get_light_properties", &GazeboApi::getLightProperties, this),
      n.advertiseService("set_light_properties", &GazeboApi::setLightProperties, this),
      n.advertiseService("delete_light", &GazeboApi::deleteLight, this),
      n.advertiseService("get_physics_properties", &GazeboApi::getPhysicsProperties, this),
      n.advertiseService("set_physics_properties", &GazeboApi::setPhysicsProperties, this),
      n.advertiseService("set_parameters", &GazeboApi::setParameters, this),
      n.advertiseService("pause_physics", &GazeboApi::pausePhysics, this),
      n.advertiseService("reset_simulation", &GazeboApi::resetSimulation, this),
      n.advertiseService("reset_world", &GazeboApi::resetWorld, this),
      // Last on purpose: clients (and our tests) take it as the sign that every service and
      // topic is up.
      n.advertiseService("unpause_physics", &GazeboApi::unpausePhysics, this),
  };
  // The world view's own service (not Gazebo's) comes and goes with its markers, which the view
  // asks for: by default the node's names are exactly Gazebo's.
  loop_.followViewMarkers([this](bool on) {
    if (on)
      reset_model_service_ =
          private_nh_.advertiseService("reset_model", &GazeboApi::resetModel, this);
    else
      reset_model_service_.shutdown();
  });
}

GazeboApi::~GazeboApi() {
  stopping_ = true;
  for (std::thread& thread : service_threads_) thread.join();
  step_spinner_.stop();
  effort_thread_.join();
}

// As roscpp's AsyncSpinner serves a queue, but ending when the queue is disabled: ros::shutdown
// disables the global queue first and then unregisters every service and topic with the master,
// for tenths of a second (longer on a busy machine), and the spinner's threads would spin on the
// disabled queue, which returns at once, all that time.
void GazeboApi::serveGlobalQueue() {
  ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
  while (!stopping_ && ros::ok()) {
    if (queue->callOne(ros::WallDuration(0.1)) == ros::CallbackQueue::Disabled) return;
  }
}

// --- joints ---------------------------------------------------------------------------------

bool GazeboApi::getJointProperties(
    Event<gazebo_msgs::GetJointProperties::Request, gazebo_msgs::GetJointProperties::Response>& event) {
  const auto& req = event.getRequest();
  auto& res = event.getResponse();
  JointInfo joint;
  const Status found = loop_.readWorldFor(event.getCallerName(), [&](const World& world) {
    return world.jointInfo(req.joint_name, &joint);
  });
  if (found.ok()) {
    res.type = toJointTypeConstant(joint.type);
    if (joint.has_damping) res.damping.push_back(joint.damping);
    res.position.push_back(joint.position);
    res.rate.push_back(joint.rate);
  }
  return answer(res, found, statusText(kGetJointProperties, found));
}

bool GazeboApi::applyJointEffort(
    Event<gazebo_msgs::ApplyJointEffort::Request, gazebo_msgs::ApplyJointEffort::Response>& event) {
  const auto& req = event.getRequest();
  auto& res = event.getResponse();
  const SimLoop::EffortResult applied = loop_.applyJointEffort(
      {event.getCallerName(), req.joint_name, req.effort, toNs(req.start_time), toNs(req.duration)});
  if (applied.joined_lockstep)
    ROS_INFO_STREAM(lockstepJoinText(req.joint_name, event.getCallerName()));
  const std::string text = statusText(kApplyJointEffort, applied.status);
  if (applied.status.ok() && applied.period_over_at_ns)
    return answer(res, applied.status, text + lockstepPeriodOverNote(*applied.period_over_at_ns));
  return answer(res, applied.status, applied.status.ok() ? text + jobNotes(applied.job) : text);
}

// Damping is served: World applies it as an effort, alike on every engine. The other fields are
// joint limits and ODE joint parameters, which the engines set when the model is spawned: a
// request that sets one is refused, naming it, and changes nothing.
bool GazeboApi::setJointProperties(gazebo_msgs::SetJointProperties::Request& req,
                                   gazebo_msgs::SetJointProperties::Response& res) {
  const auto& config = req.ode_joint_config;
  const std::pair<const char*, const std::vector<double>*> set_at_spawn[] = {
      {"hiStop", &config.hiStop},     {"loStop", &config.loStop},
      {"erp", &config.erp},           {"cfm", &config.cfm},
      {"stop_erp", &config.stop_erp}, {"stop_cfm", &config.stop_cfm},
      {"fudge_factor", &config.fudge_factor}, {"fmax", &config.fmax},
      {"vel", &config.vel}};
  JointInfo joint;
  Status status = loop_.readWorld([&](const World& world) { return world.jointInfo(req.joint_name, &joint); });
  if (!status.ok()) return refuse(res, statusText(kSetJointProperties, status));
  for (const auto& field : set_at_spawn) {
    if (!field.second->empty()) {
      return refuse(res, std::string("SetJointProperties: ") + field.first +
                             " cannot be changed: the engines set joint limits and ODE joint "
                             "parameters when the model is spawned (damping can be changed)");
    }
  }
  if (config.damping.size() > 1) {
    std::ostringstream text;
    text << "SetJointProperties: damping has " << config.damping.size()
         << " values but joint '" << req.joint_name << "' has one axis";
    return refuse(res, text.str());
  }
  if (config.damping.empty()) return succeed(res, kSetJointProperties.done);
  status = loop_.withWorld(
      [&](World& world) { return world.setJointDamping(req.joint_name, config.damping[0]); });
  if (status.code == StatusCode::JointIsFixed) {
    return refuse(res, "SetJointProperties: joint '" + status.subject + "' is fixed and has no "
                       "damping");
  }
  return answer(res, status, statusText(kSetJointProperties, status));
}

bool GazeboApi::clearJointForces(gazebo_msgs::JointRequest::Request& req, gazebo_msgs::JointRequest::Response&) {
  loop_.withWorld([&](World& world) { world.clearJointForces(req.joint_name); });
  return true;
}

// --- links ----------------------------------------------------------------------------------

bool GazeboApi::applyBodyWrench(gazebo_msgs::ApplyBodyWrench::Request& req, gazebo_msgs::ApplyBodyWrench::Response& res) {
  JobOutcome job;
  const Status applied = loop_.withWorld([&](World& world) {
    return world.applyBodyWrench(req.body_name, req.reference_frame, toCore(req.reference_point),
                                 toCore(req.wrench.force), toCore(req.wrench.torque),
                                 toNs(req.start_time), toNs(req.duration), &job);
  });
  const std::string text = wrenchText(applied);
  return answer(res, applied,
                applied.ok() ? text + jobNotes(job, std::make_pair(toCore(req.wrench.force),
                                                                   toCore(req.wrench.torque)))
                             : text);
}

bool GazeboApi::clearBodyWrenches(gazebo_msgs::BodyRequest::Request& req, gazebo_msgs::BodyRequest::Response&) {
  loop_.withWorld([&](World& world) { world.clearBodyWrenches(req.body_name); });
  return true;
}

bool GazeboApi::getLinkState(gazebo_msgs::GetLinkState::Request& req, gazebo_msgs::GetLinkState::Response& res) {
  Pose pose;
  Twist twist;
  const Status state = loop_.readWorld([&](const World& world) {
    return world.linkState(req.link_name, req.reference_frame, &pose, &twist);
  });
  if (state.ok()) {
    res.link_state.link_name = req.link_name;
    res.link_state.reference_frame = req.reference_frame;
    res.link_state.pose = toMsg(pose);
    res.link_state.twist = toMsg(twist);
  }
  return answer(res, state, statusText(kGetLinkState, state));
}

Status GazeboApi::applyLinkState(const gazebo_msgs::LinkState& state) {
  return loop_.withWorld([&](World& world) {
    return world.setLinkState(state.link_name, toCore(state.pose), toCore(state.twist),
                              state.reference_frame);
  });
}

bool GazeboApi::setLinkState(gazebo_msgs::SetLinkState::Request& req, gazebo_msgs::SetLinkState::Response& res) {
  const Status status = applyLinkState(req.link_state);
  return answer(res, status, statusText(kSetLinkState, status));
}

void GazeboApi::setLinkStateTopic(const gazebo_msgs::LinkState::ConstPtr& msg) {
  const Status status = applyLinkState(*msg);
  if (!status.ok()) ROS_WARN_STREAM(statusText(kSetLinkState, status));
}

bool GazeboApi::getLinkProperties(gazebo_msgs::GetLinkProperties::Request& req,
                                  gazebo_msgs::GetLinkProperties::Response& res) {
  LinkInfo link;
  const Status found =
      loop_.readWorld([&](const World& world) { return world.linkProperties(req.link_name, &link); });
  if (found.ok()) {
    res.com = toMsg(link.com);
    res.gravity_mode = link.gravity_mode;
    res.mass = link.mass;
    res.ixx = link.ixx;
    res.ixy = link.ixy;
    res.ixz = link.ixz;
    res.iyy = link.iyy;
    res.iyz = link.iyz;
    res.izz = link.izz;
  }
  return answer(res, found, statusText(kGetLinkProperties, found));
}

bool GazeboApi::setLinkProperties(gazebo_msgs::SetLinkProperties::Request& req,
                                  gazebo_msgs::SetLinkProperties::Response& res) {
  LinkInfo link;
  link.com = toCore(req.com);
  link.mass = req.mass;
  link.ixx = req.ixx, link.ixy = req.ixy, link.ixz = req.ixz;
  link.iyy = req.iyy, link.iyz = req.iyz, link.izz = req.izz;
  link.gravity_mode = req.gravity_mode;
  std::optional<InertiaWarning> warning;
  const Status set = loop_.withWorld(
      [&](World& world) { return world.setLinkProperties(req.link_name, link, &warning); });
  std::string text = statusText(kSetLinkProperties, set);
  if (set.ok() && warning) {
    text += "; warning: " + inertiaWarningText(*warning);
    ROS_WARN_STREAM("SetLinkProperties '" << req.link_name << "': " << inertiaWarningText(*warning));
  }
  return answer(res, set, text);
}

// --- lights ---------------------------------------------------------------------------------

// There is no renderer, so the world has no lights: every name is one that does not exist, and
// the answer is Gazebo's for that case.
bool GazeboApi::getLightProperties(gazebo_msgs::GetLightProperties::Request& req,
                                   gazebo_msgs::GetLightProperties::Response& res) {
  return refuse(res, "getLightProperties: Requested light " + req.light_name + " not found!");
}

bool GazeboApi::setLightProperties(gazebo_msgs::SetLightProperties::Request& req,
                                   gazebo_msgs::SetLightProperties::Response& res) {
  return refuse(res, "setLightProperties: Requested light " + req.light_name + " not found!");
}

bool GazeboApi::deleteLight(gazebo_msgs::DeleteLight::Request& req,
                            gazebo_msgs::DeleteLight::Response& res) {
  return refuse(res, "DeleteLight: Requested light " + req.light_name + " not found!");
}

// --- models ---------------------------------------------------------------------------------

bool GazeboApi::spawnUrdfModel(gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res) {
  return spawnModel(ModelFormat::Urdf, req, res);
}

bool GazeboApi::spawnSdfModel(gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res) {
  return spawnModel(ModelFormat::Sdf, req, res);
}

// Gazebo's spawn services both take URDF or SDF (it converts URDF to SDF); so do we, by the
// root element. `requested` only names the service in log lines.
bool GazeboApi::spawnModel(ModelFormat requested, gazebo_msgs::SpawnModel::Request& req,
                           gazebo_msgs::SpawnModel::Response& res) {
  ModelFormat format = requested;
  const Status detected = detectModelFormat(req.model_xml, &format);
  if (!detected.ok()) {
    ROS_WARN_STREAM("SpawnModel: " << detected.subject);
    return refuse(res, kNotUrdfOrSdf);
  }
  std::string missing_package;
  if (format == ModelFormat::Urdf && !resolvePackageUris(&req.model_xml, &missing_package))
    return refuse(res, "urdf reference package name does not exist: " + missing_package);
  const std::string via = requested == ModelFormat::Urdf ? "spawn_urdf_model" : "spawn_sdf_model";
  std::string warnings;
  const Status spawned = spawn(req.model_name, req.model_xml, format, toCore(req.initial_pose),
                               req.reference_frame, req.robot_namespace, via, &warnings);
  return answer(res, spawned, statusText(kSpawnModel, spawned) + warnings);
}

// The model is parsed and checked unlocked (a thousand SDF links take seconds), between two
// short locked steps that keep World::spawn's order of refusals: the name and frame first, then
// the model, then its plugins' ROS names. The model's plugins are created unlocked (they
// advertise and subscribe) and join the loop if the model is still there; robot_namespace is
// theirs where they name none. A spawn is whole or nothing: a plugin that throws as it starts
// takes the model back out of the world.
Status GazeboApi::spawn(const std::string& name, const Prepare& prepare, const std::string& xml,
                        ModelFormat format, const Pose& pose, const std::string& reference_frame,
                        const std::string& robot_namespace, const std::string& via,
                        std::string* warnings) {
  std::vector<std::string> model_path;
  std::vector<InertiaWarning> implausible;
  std::vector<std::string> left_out;
  Status spawned = loop_.withWorld([&](World& world) {
    model_path = world.modelPath();
    return world.checkSpawn(name, pose, reference_frame);
  });
  if (spawned.ok()) {
    PreparedModel prepared = prepare(model_path);
    spawned = prepared.status();
    implausible = prepared.warnings();
    left_out = prepared.leftOut();
    if (spawned.ok()) {
      const std::string bad_name = plugins::invalidPluginName(
          plugin_types_, plugins::sensorPluginRegistry(), xml, format, robot_namespace);
      if (!bad_name.empty()) spawned = {StatusCode::ModelRejected, bad_name};
    }
    if (spawned.ok())
      spawned = loop_.withWorld([&](World& world) {
        return world.spawn(name, std::move(prepared), pose, reference_frame);
      });
    prepared = PreparedModel();
    if (!loading_world_) releaseFreedMemory();
  }
  if (!spawned.ok()) return spawned;
  std::vector<std::string> plugin_problems;
  std::vector<std::unique_ptr<plugins::ModelPlugin>> created;
  try {
    created = plugins::createModelPlugins(plugin_types_, plugins::sensorPluginRegistry(), name,
                                          xml, format, robot_namespace, loop_.world(),
                                          loop_.lockWorld(), &plugin_problems);
  } catch (const std::exception& e) {
    loop_.deleteModel(name);
    releaseFreedMemory();
    ROS_ERROR_STREAM("model '" << name << "' taken back out of the world: a plugin of it failed "
                     "to start: " << e.what());
    return {StatusCode::ModelRejected,
            std::string("a plugin of the model failed to start, so the model was not spawned: ") +
                e.what()};
  }
  ROS_INFO_STREAM("spawned model '" << name << "' ("
                  << (format == ModelFormat::Urdf ? "URDF" : "SDF") << ") via " << via);
  std::vector<std::string> said;
  for (const InertiaWarning& warning : implausible) {
    ROS_WARN_STREAM("model '" << name << "': " << inertiaWarningText(warning));
    said.push_back(inertiaWarningText(warning));
  }
  // As Gazebo's "Unable to load mesh": an error, and the model goes on without the collision.
  for (const std::string& reason : left_out) {
    ROS_ERROR_STREAM("model '" << name << "': " << reason << ": the collision is left out");
    said.push_back(reason + ": the collision is left out");
  }
  // Logged as they happened; the model goes on without those plugins, as in Gazebo.
  said.insert(said.end(), plugin_problems.begin(), plugin_problems.end());
  if (warnings)
    for (const std::string& text : said) *warnings += "; warning: " + text;
  loop_.attachPlugins(name, std::move(created));
  return spawned;
}

Status GazeboApi::spawn(const std::string& name, const std::string& xml, ModelFormat format,
                        const Pose& pose, const std::string& reference_frame,
                        const std::string& robot_namespace, const std::string& via,
                        std::string* warnings) {
  const auto prepare = [&](const std::vector<std::string>& model_path) {
    return World::prepare(xml, format, model_path);
  };
  return spawn(name, prepare, xml, format, pose, reference_frame, robot_namespace, via, warnings);
}

// The heap is trimmed once, after the last model: a trim walks every free chunk of the heap, which
// the file's reading left in the millions.
void GazeboApi::spawnWorldModels(const WorldFile& world) {
  loading_world_ = true;
  struct TrimAfter {
    bool& loading;
    ~TrimAfter() {
      loading = false;
      releaseFreedMemory();
    }
  } trim_after{loading_world_};
  size_t done = 0;
  for (const WorldFileModel& model : world.models) {
    // SIGINT (roscpp's handler shuts the node down) is honoured between two models: the node
    // ends instead of loading the rest.
    if (!ros::ok()) {
      ROS_INFO_STREAM("world '" << world.name << "': shutting down; loading stopped after "
                      << done << " of its " << world.models.size() << " models");
      return;
    }
    ++done;
    const auto read_with_world = [&](const std::vector<std::string>&) {
      return World::prepare(model);
    };
    const Status spawned = spawn(model.name, read_with_world, model.sdf, ModelFormat::Sdf,
                                 model.pose, "", "", "world '" + world.name + "'");
    if (!spawned.ok())
      throw WorldModelRefused("world '" + world.name + "': model '" + model.name +
                              "' cannot be spawned: " + statusText(kSpawnModel, spawned));
  }
  if (world.state) {
    const Status clock = loop_.withWorld([&](World& w) {
      return w.setClock(world.state->sim_time_ns, world.state->iterations);
    });
    if (!clock.ok()) {
      std::ostringstream why;
      why << "world '" << world.name << "': its <state>'s <sim_time> cannot be taken: " << clock;
      throw WorldModelRefused(why.str());
    }
  }
}

bool GazeboApi::deleteModel(gazebo_msgs::DeleteModel::Request& req, gazebo_msgs::DeleteModel::Response& res) {
  const Status deleted = loop_.deleteModel(req.model_name);
  releaseFreedMemory();
  return answer(res, deleted, statusText(kDeleteModel, deleted));
}

bool GazeboApi::getModelState(gazebo_msgs::GetModelState::Request& req, gazebo_msgs::GetModelState::Response& res) {
  Pose pose;
  Twist twist;
  int64_t now_ns = 0;
  const Status state = loop_.readWorld([&](const World& world) {
    now_ns = world.timeNs();
    return world.modelState(req.model_name, req.relative_entity_name, &pose, &twist);
  });
  if (state.ok()) {
    res.header.stamp.fromNSec(uint64_t(now_ns));
    res.header.frame_id = req.relative_entity_name;
    res.pose = toMsg(pose);
    res.twist = toMsg(twist);
  }
  return answer(res, state, statusText(kGetModelState, state));
}

Status GazeboApi::applyModelState(const gazebo_msgs::ModelState& state) {
  return loop_.withWorld([&](World& world) {
    return world.setModelState(state.model_name, toCore(state.pose), toCore(state.twist),
                               state.reference_frame);
  });
}

bool GazeboApi::setModelState(gazebo_msgs::SetModelState::Request& req, gazebo_msgs::SetModelState::Response& res) {
  const Status status = applyModelState(req.model_state);
  return answer(res, status, statusText(kSetModelState, status));
}

void GazeboApi::setModelStateTopic(const gazebo_msgs::ModelState::ConstPtr& msg) {
  const Status status = applyModelState(*msg);
  if (!status.ok()) ROS_WARN_STREAM(statusText(kSetModelState, status));
}

// urdf_param_name is ignored, as Gazebo does: the model already knows its joints.
bool GazeboApi::setModelConfiguration(gazebo_msgs::SetModelConfiguration::Request& req,
                                      gazebo_msgs::SetModelConfiguration::Response& res) {
  const Status set = loop_.withWorld([&](World& world) {
    return world.setModelConfiguration(req.model_name, req.joint_names, req.joint_positions);
  });
  return answer(res, set, configurationText(set));
}

bool GazeboApi::getModelProperties(gazebo_msgs::GetModelProperties::Request& req,
                                   gazebo_msgs::GetModelProperties::Response& res) {
  ModelInfo model;
  const Status found =
      loop_.readWorld([&](const World& world) { return world.modelProperties(req.model_name, &model); });
  if (found.ok()) {
    // Bare link names, as Gazebo answers (its srv comment says scoped, its code says bare).
    res.canonical_body_name = bareName(model.canonical_link);
    for (const auto& link : model.links) res.body_names.push_back(bareName(link));
    res.geom_names = model.geoms;
    res.joint_names = model.joints;
    res.is_static = model.is_static;
  }
  return answer(res, found, statusText(kGetModelProperties, found));
}

bool GazeboApi::getWorldProperties(gazebo_msgs::GetWorldProperties::Request&,
                                   gazebo_msgs::GetWorldProperties::Response& res) {
  loop_.readWorld([&](const World& world) {
    res.sim_time = world.time();
    res.model_names = world.modelNames();
  });
  res.rendering_enabled = false;  // there is no renderer
  return succeed(res, "GetWorldProperties: got properties");
}

// --- physics --------------------------------------------------------------------------------

bool GazeboApi::getPhysicsProperties(gazebo_msgs::GetPhysicsProperties::Request&,
                                     gazebo_msgs::GetPhysicsProperties::Response& res) {
  const PhysicsSettings settings = loop_.physics();
  const PhysicsParams& p = settings.params;
  res.pause = loop_.paused();
  res.max_update_rate = settings.max_update_rate;
  res.time_step = p.step;
  res.gravity = toVector3(p.gravity);
  auto& ode = res.ode_config;
  ode.auto_disable_bodies = p.auto_disable_bodies;
  ode.sor_pgs_precon_iters = p.sor_pgs_precon_iters;
  ode.sor_pgs_iters = p.sor_pgs_iters;
  ode.sor_pgs_w = p.sor_pgs_w;
  ode.sor_pgs_rms_error_tol = p.sor_pgs_rms_error_tol;
  ode.contact_surface_layer = p.contact_surface_layer;
  ode.contact_max_correcting_vel = p.contact_max_correcting_vel;
  ode.cfm = p.cfm;
  ode.erp = p.erp;
  ode.max_contacts = p.max_contacts;
  // The message has no engine field: the status names the engine.
  return succeed(res, "GetPhysicsProperties: got properties (engine: " +
                          loop_.world().engineName() + ")");
}

Status GazeboApi::applyPhysics(const PhysicsSettings& settings, std::string* text) {
  const std::string rate_error = maxUpdateRateError(settings.max_update_rate);
  if (!rate_error.empty()) {
    *text = "SetPhysicsProperties: " + rate_error;
    return {StatusCode::InvalidParameter, "max_update_rate"};
  }
  const Status set = loop_.setPhysics(settings);
  *text = statusText(kSetPhysicsProperties, set);
  if (set.ok()) parameter_updates_pub_.publish(toConfig(loop_.physics()));
  return set;
}

bool GazeboApi::setPhysicsProperties(gazebo_msgs::SetPhysicsProperties::Request& req,
                                     gazebo_msgs::SetPhysicsProperties::Response& res) {
  PhysicsSettings settings = loop_.physics();  // keeps what ODEPhysics can't say (quick_step)
  PhysicsParams& p = settings.params;
  settings.max_update_rate = req.max_update_rate;
  p.step = req.time_step;
  p.gravity = toCore(req.gravity);
  const auto& ode = req.ode_config;
  p.auto_disable_bodies = ode.auto_disable_bodies;
  p.sor_pgs_precon_iters = ode.sor_pgs_precon_iters;
  p.sor_pgs_iters = ode.sor_pgs_iters;
  p.sor_pgs_w = ode.sor_pgs_w;
  p.sor_pgs_rms_error_tol = ode.sor_pgs_rms_error_tol;
  p.contact_surface_layer = ode.contact_surface_layer;
  p.contact_max_correcting_vel = ode.contact_max_correcting_vel;
  p.cfm = ode.cfm;
  p.erp = ode.erp;
  p.max_contacts = ode.max_contacts;
  std::string text;
  const Status set = applyPhysics(settings, &text);
  return answer(res, set, text);
}

// dynamic_reconfigure: the parameters the request names change, the others keep their values;
// the reply is the configuration in force afterwards. Reconfigure has no status field, so a
// refusal (the same checks as set_physics_properties) is logged and the reply shows nothing
// changed.
bool GazeboApi::setParameters(dynamic_reconfigure::Reconfigure::Request& req,
                              dynamic_reconfigure::Reconfigure::Response& res) {
  PhysicsSettings settings = loop_.physics();
  applyRequested(req.config, &settings);
  std::string text;
  if (!applyPhysics(settings, &text).ok()) ROS_WARN_STREAM("set_parameters: " << text);
  res.config = toConfig(loop_.physics());
  return true;
}

bool GazeboApi::pausePhysics(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  loop_.setPaused(true);
  return true;
}

bool GazeboApi::unpausePhysics(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  loop_.setPaused(false);
  return true;
}

bool GazeboApi::stepSimulation(StepSimulation::Request& req, StepSimulation::Response& res) {
  if (req.steps > SimLoop::kMaxRequestedSteps) {
    loop_.readWorld([&](const World& world) {
      res.sim_time.fromNSec(uint64_t(world.timeNs()));
      res.iterations = world.stepCount();
    });
    return refuse(res, stepsOverLimitText(req.steps, SimLoop::kMaxRequestedSteps,
                                          loop_.physics().params.step));
  }
  const SimLoop::StepsDone done = loop_.runSteps(req.steps);
  res.sim_time.fromNSec(uint64_t(done.time_ns));
  res.iterations = done.iterations;
  if (done.ended_by)
    return refuse(res, stepsEndedText(done.ended_by, done.steps, req.steps, done.time_ns));
  if (!done.done) return refuse(res, "StepSimulation: the simulator is shutting down");
  std::ostringstream text;
  text << "StepSimulation: stepped " << req.steps << " steps to sim time "
       << simSeconds(done.time_ns) << "; paused";
  return succeed(res, text.str());
}

bool GazeboApi::resetSimulation(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  loop_.resetSimulation();
  return true;
}

bool GazeboApi::resetWorld(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  loop_.resetWorld();
  return true;
}

bool GazeboApi::resetModel(ResetModel::Request& req, ResetModel::Response& res) {
  const Status reset = loop_.resetModel(req.model_name);
  return answer(res, reset, statusText(kResetModel, reset));
}

}  // namespace onedof_sim
