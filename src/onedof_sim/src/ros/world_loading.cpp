#include "world_loading.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

#include <ros/package.h>
#include <ros/ros.h>

namespace onedof_sim {
namespace {

std::string joined(const std::vector<std::string>& items) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return text;
}

// Where a relative world path is looked for, in order.
std::vector<std::string> resourceFolders() {
  std::vector<std::string> folders{std::filesystem::current_path().string(),
                                   ros::package::getPath("onedof_sim")};
  const char* env = std::getenv("GAZEBO_RESOURCE_PATH");
  std::istringstream entries(env ? env : "");
  for (std::string folder; std::getline(entries, folder, ':');)
    if (!folder.empty()) folders.push_back(folder);
  return folders;
}

// The file `given` names, or "" with the folders searched in *searched.
std::string findWorldFile(const std::string& given, std::vector<std::string>* searched) {
  namespace fs = std::filesystem;
  std::error_code ignored;
  if (fs::path(given).is_absolute()) return fs::exists(given, ignored) ? given : "";
  for (const std::string& folder : resourceFolders()) {
    const fs::path candidate = fs::path(folder) / given;
    if (fs::exists(candidate, ignored)) return candidate.string();
    searched->push_back(folder);
  }
  return "";
}

std::string whyNotLoaded(const WorldFileStatus& status,
                         const std::vector<std::string>& model_path) {
  switch (status.code) {
    case WorldFileCode::Ok: return "loaded";
    case WorldFileCode::NotFound: return "no such file";
    case WorldFileCode::Unreadable: return "the file cannot be read";
    case WorldFileCode::NotAFile:
      return "it is a " + status.subject + ", not a regular file: a world file is an SDF file";
    case WorldFileCode::TooLarge: {
      std::ostringstream text;
      text << "the file is larger than " << status.max << " bytes";
      return text.str();
    }
    case WorldFileCode::InvalidXml: return "not well-formed XML: " + status.subject;
    case WorldFileCode::NotSdf:
      if (status.subject.rfind("<gazebo", 0) == 0)
        return "its root element is " + status.subject + ", Gazebo 1's world format from before "
               "SDF, which libsdformat (and so Gazebo 11) no longer reads; an SDF world's root is "
               "<sdf version=\"...\">";
      return "its root element is " + status.subject + ", not <sdf>";
    case WorldFileCode::InvalidSdf: return "invalid SDF: " + status.subject;
    case WorldFileCode::InvalidState:
      return "<state>: " + status.subject + " is not a time within [0, 2^32) s";
    case WorldFileCode::NoWorld:
      return "the file has " + status.subject + ", no <world> (spawn a model file with "
             "rosrun gazebo_ros spawn_model)";
    case WorldFileCode::NegativeCount:
      return "<physics>: <" + status.subject + "> is a count and must be >= 0";
    case WorldFileCode::IncludeNotFound:
      return "<include> " + status.subject + " is not in the model path or is no readable "
             "regular file (" + joined(model_path) +
             "; add a folder to GAZEBO_MODEL_PATH)";
    case WorldFileCode::IncludeCycle:
      return "its <include>s include themselves: " + status.subject;
    case WorldFileCode::TooManyIncludedModels: {
      std::ostringstream text;
      text << "its <include>s, nested ones counted each time, place " << status.subject
           << " models; at most " << status.max << " are accepted";
      return text.str();
    }
    case WorldFileCode::TooManyModels: {
      std::ostringstream text;
      text << "the world places " << status.subject << " models; at most " << status.max
           << " are accepted";
      return text.str();
    }
  }
  return "unknown error";
}

// gazebo_ros' system plugins, which some worlds load as world plugins: what they serve, the node
// serves.
const std::set<std::string> kRosApiPlugins = {"libgazebo_ros_api_plugin.so",
                                              "libgazebo_ros_paths_plugin.so"};

// One line per kind of element the world holds that is not simulated: what Gazebo would only
// show or render is said at INFO; a world plugin, which Gazebo would run, is an error as Gazebo
// logs a plugin it cannot load.
void logIgnored(const WorldFile& world) {
  std::vector<std::string> lights, others;
  for (const WorldFileIgnored& element : world.ignored) {
    if (element.element == "light") {
      lights.push_back("'" + element.name + "'");
    } else if (element.element == "plugin" && kRosApiPlugins.count(element.filename)) {
      ROS_INFO_STREAM("world '" << world.name << "': plugin '" << element.name << "' ("
                      << element.filename << "): gazebo_ros' API is this simulator's own");
    } else if (element.element == "plugin") {
      ROS_ERROR_STREAM("world '" << world.name << "': Failed to load plugin " << element.filename
                       << " (plugin '" << element.name << "'): this simulator runs no world "
                       "plugins; the world loads without it");
    } else if (std::find(others.begin(), others.end(), "<" + element.element + ">") ==
               others.end()) {
      others.push_back("<" + element.element + ">");
    }
  }
  if (!lights.empty())
    ROS_INFO_STREAM("world '" << world.name << "': light" << (lights.size() > 1 ? "s " : " ")
                    << joined(lights) << " accepted, not simulated: there is no renderer");
  if (!others.empty())
    ROS_INFO_STREAM("world '" << world.name << "': not simulated: " << joined(others)
                    << " (no renderer nor GUI; no atmosphere, wind, magnetic field, audio or "
                       "actors)");
}

// The saved <state>, as Gazebo's World::Load applies it; a model it names that the world does
// not place is an error, as Gazebo logs it.
void logState(const WorldFile& world) {
  if (!world.state) return;
  const WorldFileState& state = *world.state;
  for (const std::string& name : state.unknown_models)
    ROS_ERROR_STREAM("world '" << world.name << "': <state>: Unable to find model[" << name
                     << "]");
  for (const std::string& change : state.not_applied)
    ROS_WARN_STREAM("world '" << world.name << "': <state>: its <" << change
                    << "> are not applied (this simulator does not play logs)");
  std::ostringstream time;
  time << state.sim_time_ns * 1e-9;
  ROS_INFO_STREAM("world '" << world.name << "': saved <state> applied: sim time " << time.str()
                  << " s, iteration " << state.iterations
                  << ", each model where the state puts it");
}

}  // namespace

bool loadWorldFile(const std::string& given, const std::vector<std::string>& model_path,
                   const PhysicsParams& base, WorldFile* out, std::string* error) {
  std::vector<std::string> searched;
  const std::string path = findWorldFile(given, &searched);
  if (path.empty()) {
    *error = "world file '" + given + "' not found" +
             (searched.empty() ? "" : " (looked in " + joined(searched) + ")");
    return false;
  }
  const WorldFileStatus status = readWorldFile(path, model_path, base, out);
  if (!status.ok()) {
    *error = "world file '" + path + "' cannot be loaded: " + whyNotLoaded(status, model_path);
    return false;
  }
  const std::string physics =
      out->physics_type.empty() ? "" : ", <physics type='" + out->physics_type + "'>";
  ROS_INFO_STREAM("world '" << out->name << "' from " << path << ": " << out->models.size()
                  << " model" << (out->models.size() == 1 ? "" : "s") << physics);
  logIgnored(*out);
  logState(*out);
  return true;
}

}  // namespace onedof_sim
