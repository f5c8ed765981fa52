// What the readers of SDF documents share (model_loader.cpp and world_file.cpp): one parser at a
// time, the model path as libsdformat takes it, its errors and its version check. Private to the
// core.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include <ignition/math/Pose3.hh>
#include <sdf/sdf.hh>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

// Held by every urdfdom and libsdformat parse: models are prepared on any thread.
std::mutex& parserMutex();

// A libsdformat pose, its rotation normalised.
Pose toPose(const ignition::math::Pose3d& pose);

// libsdformat's errors, joined with "; ".
std::string joinErrors(const sdf::Errors& errors);

// model://NAME looked up as FOLDER/NAME in each folder of model_path, in order; each URI found
// nowhere is appended to *missing (libsdformat only records it).
sdf::ParserConfig modelPathConfig(const std::vector<std::string>& model_path,
                                  std::vector<std::string>* missing);

// ModelRejected when the document's SDF version is newer than libsdformat reads.
Status checkSdfVersion(const sdf::Root& root);

}  // namespace core
}  // namespace onedof_sim
