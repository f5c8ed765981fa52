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

// An SDF document read as Gazebo classic reads it: libsdformat's element API (sdf::readFile,
// sdf::readString), which takes what its DOM refuses (a <material><script> without <uri> and
// <name>, which Gazebo shows as no named material; camera formats the DOM does not list; ...),
// then the DOM over those elements for frames and poses, as Gazebo resolves poses with it. The
// DOM's own errors are Gazebo's to ignore too, bar the ones refusedDomError names. What
// libsdformat warns of (an attribute the schema does not define, ...) it prints itself, as under
// Gazebo.
struct SdfDocument {
  sdf::SDFPtr elements;
  sdf::Root root;
  std::vector<std::string> missing;  // the model:// URIs found in no folder of the model path
  std::string error;                 // why it cannot be read; empty when it was read
};
enum class SdfSource { File, String };
// source: the file's absolute path (libsdformat tries a relative one against its schema folder
// first), or the document itself. The caller holds parserMutex().
void readSdfDocument(const std::string& source, SdfSource kind,
                     const std::vector<std::string>& model_path, SdfDocument* out);

}  // namespace core
}  // namespace onedof_sim
