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

struct ModelDescription;

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

enum class SdfSource { File, String };

// A document's <include>s followed through the files they name (model://NAME as libsdformat
// finds it: FOLDER/NAME's model.config or model.sdf), each file read once with tinyxml2: the
// models they place, nested includes counted each time their includer is placed, and a file
// that includes itself, directly or through others. libsdformat follows includes by recursion,
// reading each placement again: a cycle never ends, and a file that includes another twice, 17
// deep, places 2^17 models.
struct IncludeCheck {
  enum class Code { Ok, Cycle, TooMany, NotFound };
  Code code = Code::Ok;
  // Cycle: the files around it, "A -> B -> A"; NotFound: a URI refused as one found nowhere: a
  // model:// URI whose path climbs out of the model path once normalised, or one whose file (or
  // its folder's model.config) is there but no readable regular file (regular_file.h)
  std::string subject;
  size_t count = 0;     // TooMany: the models placed
  bool at_least = false;  // TooMany: count is a lower bound (more files than models accepted)
  bool ok() const { return code == Code::Ok; }
};
// source and kind as for readSdfDocument; Ok when the includes place at most max_models.
IncludeCheck checkIncludes(const std::string& source, SdfSource kind,
                           const std::vector<std::string>& model_path, size_t max_models);

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
  IncludeCheck includes;             // not Ok: refused before libsdformat read it
  std::string error;                 // why it cannot be read; empty when it was read
};
// source: the file's absolute path (libsdformat tries a relative one against its schema folder
// first), or the document itself. Its includes are checked first (checkIncludes, at most
// kMaxIncludedModels). The caller holds parserMutex().
void readSdfDocument(const std::string& source, SdfSource kind,
                     const std::vector<std::string>& model_path, SdfDocument* out);

// A model libsdformat has read (parseSdf's document's, or a world file's) made into a description:
// its links, joints and nested models, their meshes read, its canonical link, and the checks of
// its tree (ModelRejected and why). Its own <pose> is left to the caller (out->pose is the
// identity). The caller holds parserMutex().
Status describeSdfModel(const sdf::Model& model, const std::vector<std::string>& model_path,
                        ModelDescription* out);

}  // namespace core
}  // namespace onedof_sim
