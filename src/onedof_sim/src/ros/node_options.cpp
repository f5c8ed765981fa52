#include "node_options.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace onedof_sim {
namespace {

// Pacing below one step per wall second leaves the clock crawling (0.01: a step every 100 s, with
// nothing to see); pause_physics is what stops the world.
constexpr double kMinPacedRate = 1.0;

// Reads ~name into *value when set; a value of the wrong type is an error, not a silent default.
template <class T>
bool readParam(const ros::NodeHandle& nh, const std::string& name, T* value, std::string* error) {
  if (!nh.hasParam(name) || nh.getParam(name, *value)) return true;
  *error = "parameter " + nh.resolveName(name) + " has the wrong type";
  return false;
}

bool readCount(const ros::NodeHandle& nh, const std::string& name, uint32_t* value,
               std::string* error) {
  int count = int(*value);
  if (!readParam(nh, name, &count, error)) return false;
  if (count < 0) {
    *error = "parameter " + nh.resolveName(name) + " must be >= 0";
    return false;
  }
  *value = uint32_t(count);
  return true;
}

bool readRate(const ros::NodeHandle& nh, const std::string& name, double* value,
              std::string* error) {
  if (!readParam(nh, name, value, error)) return false;
  if (!std::isfinite(*value) || *value < 0) {
    *error = "parameter " + nh.resolveName(name) + " must be finite and >= 0";
    return false;
  }
  return true;
}

bool readMaxUpdateRate(const ros::NodeHandle& nh, double* value, std::string* error) {
  if (!readRate(nh, "max_update_rate", value, error)) return false;
  const std::string why = maxUpdateRateError(*value);
  if (!why.empty()) *error = "parameter " + nh.resolveName("max_update_rate") + ": " + why;
  return why.empty();
}

bool readLockstep(const ros::NodeHandle& nh, Lockstep::Options* lockstep, std::string* error) {
  double timeout = std::chrono::duration<double>(lockstep->timeout).count();
  if (!readParam(nh, "lockstep", &lockstep->enabled, error) ||
      !readParam(nh, "lockstep_timeout", &timeout, error)) {
    return false;
  }
  if (!(timeout > 0) || !std::isfinite(timeout)) {
    *error = "parameter " + nh.resolveName("lockstep_timeout") + " must be a finite number of seconds > 0";
    return false;
  }
  lockstep->timeout = std::chrono::duration_cast<Lockstep::Clock::duration>(
      std::chrono::duration<double>(timeout));
  return true;
}

// ~gravity as a list [x, y, z] (rosparam, launch files) or a string "x y z" / "[x, y, z]" (what
// _gravity:=... on the rosrun command line gives, as roscpp does not parse lists there).
bool readGravity(const ros::NodeHandle& nh, Vec3* gravity, std::string* error) {
  if (!nh.hasParam("gravity")) return true;
  std::vector<double> values;
  std::string text;
  if (!nh.getParam("gravity", values) && nh.getParam("gravity", text)) {
    for (char& c : text) {
      if (c == '[' || c == ']' || c == ',') c = ' ';
    }
    std::istringstream in(text);
    double value;
    while (in >> value) values.push_back(value);
    if (!in.eof()) values.clear();
  }
  if (values.size() != 3) {
    *error = "parameter " + nh.resolveName("gravity") + " must be three numbers [x, y, z]";
    return false;
  }
  *gravity = {values[0], values[1], values[2]};
  return true;
}

// The master's parameter server, by the parameter's global name with no remapping applied.
bool masterHasParam(const std::string& name) {
  XmlRpc::XmlRpcValue request, response, has;
  request[0] = ros::this_node::getName();
  request[1] = name;
  return ros::master::execute("hasParam", request, response, has, false) && bool(has);
}

void masterSetParam(const std::string& name, bool value) {
  XmlRpc::XmlRpcValue request, response, unused;
  request[0] = ros::this_node::getName();
  request[1] = name;
  request[2] = value;
  ros::master::execute("setParam", request, response, unused, false);
}

// gzserver's flags that take a value: the value is not the world file.
const char* const kFlagsWithValue[] = {"-e", "--physics", "-s", "--server-plugin", "-p", "--play",
                                       "--seed", "--iters", "-o", "--profile", "--record_path",
                                       "--record_period", "--record_filter", "--record_encoding"};

bool takesValue(const std::string& flag) {
  for (const char* known : kFlagsWithValue)
    if (flag == known) return true;
  return false;
}

}  // namespace

std::string maxUpdateRateError(double rate) {
  if (rate == 0 || (rate >= kMinPacedRate && rate <= kMaxPacedRate)) return "";
  std::ostringstream text;
  text << "max_update_rate must be 0 (as fast as possible) or between " << kMinPacedRate
       << " and " << kMaxPacedRate << " steps per wall second (pause_physics stops the world), got "
       << rate;
  return text.str();
}

ServerArguments parseServerArguments(const std::vector<std::string>& args) {
  ServerArguments parsed;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "-u" || arg == "--pause") {
      parsed.paused = true;
    } else if ((arg == "-e" || arg == "--physics") && i + 1 < args.size()) {
      parsed.engine = args[++i];
    } else if (!arg.empty() && arg[0] != '-') {
      if (!parsed.world_file.empty())
        ROS_WARN_STREAM("ignoring command-line argument '" << parsed.world_file
                        << "': the world file is the last one, '" << arg << "'");
      parsed.world_file = arg;
    } else if (takesValue(arg) && i + 1 < args.size()) {
      ROS_WARN_STREAM("ignoring command-line argument '" << arg << " " << args[i + 1] << "'");
      ++i;
    } else {
      ROS_WARN_STREAM("ignoring command-line argument '" << arg << "'");
    }
  }
  return parsed;
}

// Private start-up parameters (all optional; set them before starting the node, on the command
// line as _name:=value, or in a launch file):
//   ~physics (the engine: World::engineNames(), the first by default or when empty; gzserver's -e does the same;
//     World refuses an unknown one, naming the known ones)
//   ~time_step (s, 0.001)  ~max_update_rate (steps per wall second, 1000; 0 = as fast as possible)
//   ~paused (false; gzserver's -u / --pause flag does the same)  ~gravity ([0, 0, -9.8], or "0 0 -9.8")
//   ~quick_step (false: dWorldStep; true: dWorldQuickStep)
//   ODE solver settings named as the fields of ODEPhysics: ~auto_disable_bodies,
//   ~sor_pgs_precon_iters, ~sor_pgs_iters, ~sor_pgs_w, ~sor_pgs_rms_error_tol,
//   ~contact_surface_layer, ~contact_max_correcting_vel, ~cfm, ~erp, ~max_contacts
//   ~states_publish_frequency (Hz of sim time for model_states/link_states; 0 = every step)
//   ~lockstep (false; see lockstep.h)
//   ~lockstep_timeout (wall s a stopped world waits for a controller's command, 5)
//   ~enable_ros_network (true; false: no /gazebo service nor topic, as Gazebo's, NodeOptions)
//   ~enable_step_simulation (~lockstep's value)  ~enable_collision_markers (false; NodeOptions)
// and, read while running, ~pub_clock_frequency (Hz of sim time; unset or <= 0 = every step) and
// ~enable_collision_markers.
// A world file's physics (options->world) comes between the defaults and these: the engine its
// <physics type> names unless ~physics or -e names one, its physics for that engine and its
// real_time_update_rate unless a parameter sets them.
bool readNodeOptions(const ros::NodeHandle& nh, const ServerArguments& arguments,
                     NodeOptions* options, std::string* error) {
  std::string engine;
  if (!readParam(nh, "physics", &engine, error)) return false;
  if (!arguments.engine.empty()) engine = arguments.engine;
  const std::vector<std::string> engines = World::engineNames();
  if (engine.empty() && options->world && !options->world->physics_type.empty()) {
    engine = options->world->physics_type;
    if (std::find(engines.begin(), engines.end(), engine) == engines.end()) {
      std::string known;
      for (const std::string& name : engines) known += (known.empty() ? "" : ", ") + name;
      *error = "the world file's <physics type='" + engine + "'> is not an engine of this "
               "simulator (" + known + "); choose one with physics:= or -e";
      return false;
    }
  }
  // Empty (a launch file's physics:= left at its default, no world file's type): the default.
  options->engine = engine.empty() ? engines.front() : engine;
  if (options->world) {
    const auto physics = options->world->physics.find(options->engine);
    if (physics != options->world->physics.end()) options->physics = physics->second;
    if (const auto& rate = options->world->real_time_update_rate) {
      const std::string why = maxUpdateRateError(*rate);
      if (!why.empty()) {
        *error = "the world file's <real_time_update_rate>: " + why;
        return false;
      }
      options->max_update_rate = *rate;
    }
  }
  PhysicsParams& p = options->physics;
  if (!readParam(nh, "time_step", &p.step, error) ||
      !readMaxUpdateRate(nh, &options->max_update_rate, error) ||
      !readParam(nh, "paused", &options->paused, error) ||
      !readGravity(nh, &p.gravity, error) ||
      !readParam(nh, "quick_step", &p.quick_step, error) ||
      !readParam(nh, "auto_disable_bodies", &p.auto_disable_bodies, error) ||
      !readCount(nh, "sor_pgs_precon_iters", &p.sor_pgs_precon_iters, error) ||
      !readCount(nh, "sor_pgs_iters", &p.sor_pgs_iters, error) ||
      !readParam(nh, "sor_pgs_w", &p.sor_pgs_w, error) ||
      !readParam(nh, "sor_pgs_rms_error_tol", &p.sor_pgs_rms_error_tol, error) ||
      !readParam(nh, "contact_surface_layer", &p.contact_surface_layer, error) ||
      !readParam(nh, "contact_max_correcting_vel", &p.contact_max_correcting_vel, error) ||
      !readParam(nh, "cfm", &p.cfm, error) || !readParam(nh, "erp", &p.erp, error) ||
      !readCount(nh, "max_contacts", &p.max_contacts, error) ||
      !readRate(nh, "states_publish_frequency", &options->states_publish_frequency, error) ||
      !readLockstep(nh, &options->lockstep, error) ||
      !readParam(nh, "enable_ros_network", &options->enable_ros_network, error)) {
    return false;
  }
  options->enable_step_simulation = options->lockstep.enabled;
  if (!readParam(nh, kEnableStepSimulation, &options->enable_step_simulation, error) ||
      !readParam(nh, kEnableCollisionMarkers, &options->enable_collision_markers, error)) {
    return false;
  }
  if (arguments.paused) options->paused = true;
  return true;
}

void setUseSimTimeUnlessSet() {
  if (!masterHasParam(kUseSimTime)) masterSetParam(kUseSimTime, true);
}

}  // namespace onedof_sim
