// An SDF <world> file read into what the simulator makes of it, free of ROS: its name, its
// physics and gravity, the models it places (its <model>s and its <include>s of model://NAME,
// each one SDF document for World::prepare), a saved world's <state> and the elements the
// simulator does not act on. It is read as Gazebo classic reads it (libsdformat's element API;
// see src/core/sdf_parsing.h).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "onedof_sim/world.h"

namespace onedof_sim {

// A model the world places: one SDF <model> with its includes resolved, without its own <pose>
// (spawn it at `pose`). The file is read once: World::prepare(const WorldFileModel&) makes the
// model from what that reading gave.
struct WorldFileModel {
  std::string name;  // the <model>'s name, or the <include>'s <name> over the included model's
  // An SDF document of the one model: what its plugins and sensors read, and what
  // World::prepare(sdf, ModelFormat::Sdf, model path) makes the same model of.
  std::string sdf;
  Pose pose;         // the model frame in the world (an <include>'s <pose> over the model's)
  // Ok, or why the model cannot be made (ModelRejected: a limit, a link or joint refused), as
  // World::prepare would refuse sdf.
  Status read;
  std::shared_ptr<const core::ModelDescription> description;  // when read is Ok
};

// An element of the world the simulator does not act on, as the file gives it, in file order.
struct WorldFileIgnored {
  std::string element;   // "light", "plugin", "scene", "gui", "atmosphere", ...
  std::string name;      // its name attribute, if it has one
  std::string filename;  // a <plugin>'s filename
};

// A saved world's first <state> (what Gazebo's "Save World" writes), as Gazebo's World::Load
// applies it: its clock, for World::setClock; its models' poses are the models' `pose` already.
struct WorldFileState {
  int64_t sim_time_ns = 0;
  uint64_t iterations = 0;
  std::vector<std::string> unknown_models;  // named by the state, not placed by the world
  std::vector<std::string> not_applied;     // "insertions", "deletions"
};

struct WorldFile {
  std::string name;          // <world name>
  std::string physics_type;  // <physics type> ("ode", "bullet", ...); empty without <physics>
  // For each engine of World::engineNames(): the base parameters readWorldFile was given with
  // what the file sets over them: <physics>'s max_step_size and max_contacts, the engine's own
  // block (<ode> for "ode", <bullet> for "bullet": solver and constraints) and the world's
  // <gravity>. A field the file does not set keeps the base value.
  std::map<std::string, PhysicsParams> physics;
  std::optional<double> real_time_update_rate;  // steps per wall second, when the file sets it
  std::vector<WorldFileModel> models;           // in file order
  std::optional<WorldFileState> state;
  std::vector<WorldFileIgnored> ignored;
};

enum class WorldFileCode {
  Ok,
  NotFound,         // subject: the path; no such file
  Unreadable,       // subject: the path; it exists but cannot be read
  NotAFile,         // subject: what the path is instead of a regular file: "directory", "FIFO",
                    // "character device", "block device", "socket" (never opened nor read)
  TooLarge,         // subject: the path; max: the most bytes a world file may have
  InvalidXml,       // subject: why the XML is not well-formed (tinyxml2's words, with the line)
  NotSdf,           // subject: the root element (<gazebo version="1.0">: Gazebo 1's format)
  InvalidSdf,       // subject: why libsdformat refuses the document
  InvalidState,     // subject: the <state> element that is not a state (a <sim_time> past ROS time)
  NoWorld,          // subject: the root's content; the document has no <world>
  NegativeCount,    // subject: the <physics> element (iters, precon_iters, max_contacts) < 0
  IncludeNotFound,  // subject: the <include>'s URI, found in no folder of the model path
  TooManyModels,    // subject: the count; max: the most models a world may place
  IncludeCycle,     // subject: the files around a cycle of <include>s, "A -> B -> A"
  TooManyIncludedModels,  // subject: the models its <include>s place, nested ones each time
                          // ("at least N" when counting stopped early); max: the most accepted
};

struct WorldFileStatus {
  WorldFileCode code = WorldFileCode::Ok;
  std::string subject;
  double max = 0;
  bool ok() const { return code == WorldFileCode::Ok; }
};

// Reads the world file at `path` (libsdformat; a relative <uri> is taken from the file's folder)
// with model://NAME looked up in model_path's folders, in order. Fills *out only on success. The
// models are not checked here: World::prepare and World::spawn refuse a model as for a spawn.
WorldFileStatus readWorldFile(const std::string& path, const std::vector<std::string>& model_path,
                              const PhysicsParams& base, WorldFile* out);

}  // namespace onedof_sim
