// SDF world files (libsdformat 12) to WorldFile.
#include "onedof_sim/world_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>

#include <ignition/math/Pose3.hh>
#include <tinyxml2.h>

#include "model_description.h"
#include "regular_file.h"
#include "sdf_parsing.h"

namespace onedof_sim {
namespace {

using core::kEndOfTimeNs;
using core::kMaxModelXmlBytes;
using core::kMaxWorldModels;

// The world's own children the simulator acts on: the rest is listed as ignored.
const std::set<std::string> kActedOn = {"physics", "gravity", "model", "frame", "state"};

// The child `name` of parent when the file sets it (libsdformat adds the required ones it does
// not set, with their defaults, which must not override the base).
sdf::ElementPtr setInFile(const sdf::ElementPtr& parent, const char* name) {
  if (!parent || !parent->HasElement(name)) return nullptr;
  sdf::ElementPtr child = parent->GetElement(name);
  return child->GetExplicitlySetInFile() ? child : nullptr;
}

// Walks parent/names[0]/names[1]/..., each set in the file.
sdf::ElementPtr setInFile(sdf::ElementPtr element, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    element = setInFile(element, name);
    if (!element) return nullptr;
  }
  return element;
}

template <class T>
void readValue(const sdf::ElementPtr& element, T* value) {
  if (element) *value = element->Get<T>();
}

// A count the file sets below 0 is recorded in *negative (its element's name) and not taken.
void readCount(const sdf::ElementPtr& element, uint32_t* value, std::string* negative) {
  if (!element) return;
  const int count = element->Get<int>();
  if (count >= 0)
    *value = uint32_t(count);
  else if (negative->empty())
    *negative = element->GetName();
}

// <ode>: solver (type quick or world, iters, precon_iters, sor) and constraints.
void readOdeBlock(const sdf::ElementPtr& ode, PhysicsParams* p, std::string* negative) {
  if (const sdf::ElementPtr type = setInFile(ode, {"solver", "type"}))
    p->quick_step = type->Get<std::string>() != "world";
  readCount(setInFile(ode, {"solver", "iters"}), &p->sor_pgs_iters, negative);
  readCount(setInFile(ode, {"solver", "precon_iters"}), &p->sor_pgs_precon_iters, negative);
  readValue(setInFile(ode, {"solver", "sor"}), &p->sor_pgs_w);
  readValue(setInFile(ode, {"constraints", "cfm"}), &p->cfm);
  readValue(setInFile(ode, {"constraints", "erp"}), &p->erp);
  readValue(setInFile(ode, {"constraints", "contact_max_correcting_vel"}),
            &p->contact_max_correcting_vel);
  readValue(setInFile(ode, {"constraints", "contact_surface_layer"}), &p->contact_surface_layer);
}

// <bullet>: solver (iters, sor) and constraints, onto the fields the Bullet engine reads.
void readBulletBlock(const sdf::ElementPtr& bullet, PhysicsParams* p, std::string* negative) {
  readCount(setInFile(bullet, {"solver", "iters"}), &p->sor_pgs_iters, negative);
  readValue(setInFile(bullet, {"solver", "sor"}), &p->sor_pgs_w);
  readValue(setInFile(bullet, {"constraints", "cfm"}), &p->cfm);
  readValue(setInFile(bullet, {"constraints", "erp"}), &p->erp);
  readValue(setInFile(bullet, {"constraints", "contact_surface_layer"}), &p->contact_surface_layer);
}

WorldFileStatus readPhysics(const sdf::World& world, const PhysicsParams& base, WorldFile* out) {
  const sdf::ElementPtr world_element = world.Element();
  const sdf::Physics* physics = world.PhysicsDefault();
  sdf::ElementPtr element = physics ? physics->Element() : nullptr;
  if (element && !element->GetExplicitlySetInFile()) element = nullptr;
  if (element) out->physics_type = physics->EngineType();
  PhysicsParams common = base;
  readValue(setInFile(element, "max_step_size"), &common.step);
  std::string negative;
  readCount(setInFile(element, "max_contacts"), &common.max_contacts, &negative);
  if (setInFile(world_element, "gravity")) {
    const ignition::math::Vector3d g = world.Gravity();
    common.gravity = {g.X(), g.Y(), g.Z()};
  }
  if (const sdf::ElementPtr rate = setInFile(element, "real_time_update_rate"))
    out->real_time_update_rate = rate->Get<double>();
  for (const std::string& engine : World::engineNames()) {
    PhysicsParams params = common;
    if (engine == "ode") readOdeBlock(setInFile(element, "ode"), &params, &negative);
    if (engine == "bullet") readBulletBlock(setInFile(element, "bullet"), &params, &negative);
    out->physics[engine] = params;
  }
  if (!negative.empty()) return {WorldFileCode::NegativeCount, negative};
  return {};
}

// The model alone: its element without its <pose>, which is the world's business (it may be
// relative to the world's frames), as an SDF document. Its elements are in this libsdformat's
// version already; the document says the version its file gave, which converts to them
// unchanged, so that it is read again with that version's leniency (libsdformat 12 renames a
// joint named as a link in a file older than 1.8, and refuses it in a newer one).
// The <pose> is left out of the element's text, not of a clone of the element: a clone copies
// the schema's whole description of a model with it (a thousand elements), for each model.
std::string modelDocument(const sdf::Model& model) {
  const std::string& original = model.Element()->OriginalVersion();
  const std::string version = original.empty() ? sdf::SDF::Version() : original;
  const std::string text = "<?xml version=\"1.0\"?>\n<sdf version=\"" + version + "\">\n" +
                           model.Element()->ToString("") + "</sdf>\n";
  tinyxml2::XMLDocument document;
  if (document.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS) return text;
  tinyxml2::XMLElement* element = document.RootElement()->FirstChildElement("model");
  while (tinyxml2::XMLElement* pose = element ? element->FirstChildElement("pose") : nullptr)
    element->DeleteChild(pose);
  tinyxml2::XMLPrinter printer;
  document.Print(&printer);
  return printer.CStr();
}

// A root element other than <sdf>, with its version attribute if it has one.
std::string rootDescription(const tinyxml2::XMLElement& root) {
  const char* version = root.Attribute("version");
  return "<" + std::string(root.Name()) +
         (version ? " version=\"" + std::string(version) + "\"" : "") + ">";
}

// The models the file's first <world> places, its <model>s and <include>s, counted on the XML so
// that a world of too many is refused before libsdformat builds each of them.
size_t placedModels(const tinyxml2::XMLDocument& xml) {
  const tinyxml2::XMLElement* root = xml.RootElement();
  const tinyxml2::XMLElement* world = root ? root->FirstChildElement("world") : nullptr;
  size_t count = 0;
  for (const tinyxml2::XMLElement* child = world ? world->FirstChildElement() : nullptr; child;
       child = child->NextSiblingElement()) {
    const std::string name = child->Name();
    if (name == "model" || name == "include") ++count;
  }
  return count;
}

// Each model described from the file's own elements, as World::prepare would describe its
// document: the limits checked on the document's XML first, then the model itself.
WorldFileStatus readModels(const sdf::World& world, const std::vector<std::string>& model_path,
                           WorldFile* out) {
  for (uint64_t i = 0; i < world.ModelCount(); ++i) {
    const sdf::Model& model = *world.ModelByIndex(i);
    ignition::math::Pose3d pose;
    const sdf::Errors errors = model.SemanticPose().Resolve(pose, "world");
    if (!errors.empty())
      return {WorldFileCode::InvalidSdf,
              "model '" + model.Name() + "': " + core::joinErrors(errors)};
    WorldFileModel placed{model.Name(), modelDocument(model), core::toPose(pose), {}, nullptr};
    placed.read = core::precheckModelXml(placed.sdf, ModelFormat::Sdf);
    if (placed.read.ok()) {
      auto description = std::make_shared<core::ModelDescription>();
      const std::lock_guard<std::mutex> one_parser(core::parserMutex());
      placed.read = core::describeSdfModel(model, model_path, description.get());
      if (placed.read.ok()) placed.description = std::move(description);
    }
    out->models.push_back(std::move(placed));
  }
  return {};
}

// SDF's time, "sec nsec" (or "sec"), in nanoseconds; false for text that is not one.
bool readTime(const std::string& text, int64_t* time_ns) {
  std::istringstream in(text);
  double sec = 0, nsec = 0;
  if (!(in >> sec)) return false;
  if (!(in >> nsec)) nsec = 0;
  const double total = sec * 1e9 + nsec;
  if (!std::isfinite(total) || total < 0 || total >= double(kEndOfTimeNs)) return false;
  *time_ns = int64_t(std::llround(total));
  return true;
}

// The first <state> of a saved world, as Gazebo's World::Load applies it: the clock, and each
// model where the state puts it (its <pose>, the model frame in the world).
WorldFileStatus readState(const sdf::ElementPtr& world, WorldFile* out) {
  const sdf::ElementPtr state = setInFile(world, "state");
  if (!state) return {};
  WorldFileState applied;
  if (const sdf::ElementPtr time = setInFile(state, "sim_time"))
    if (!readTime(time->GetValue()->GetAsString(), &applied.sim_time_ns))
      return {WorldFileCode::InvalidState, "<sim_time> " + time->GetValue()->GetAsString()};
  if (const sdf::ElementPtr iterations = setInFile(state, "iterations"))
    applied.iterations = iterations->Get<uint64_t>();
  for (sdf::ElementPtr model = state->HasElement("model") ? state->GetElement("model") : nullptr;
       model; model = model->GetNextElement("model")) {
    const std::string name = model->Get<std::string>("name");
    auto placed = std::find_if(out->models.begin(), out->models.end(),
                               [&](const WorldFileModel& m) { return m.name == name; });
    if (placed == out->models.end()) {
      applied.unknown_models.push_back(name);
      continue;
    }
    if (setInFile(model, "pose")) placed->pose = core::toPose(model->Get<ignition::math::Pose3d>("pose"));
  }
  for (const char* change : {"insertions", "deletions"})
    if (setInFile(state, change)) applied.not_applied.push_back(change);
  out->state = applied;
  return {};
}

void listIgnored(const sdf::World& world, WorldFile* out) {
  for (sdf::ElementPtr child = world.Element()->GetFirstElement(); child;
       child = child->GetNextElement()) {
    if (!child->GetExplicitlySetInFile() || kActedOn.count(child->GetName())) continue;
    WorldFileIgnored ignored{child->GetName(), "", ""};
    if (child->HasAttribute("name")) ignored.name = child->GetAttribute("name")->GetAsString();
    if (child->HasAttribute("filename"))
      ignored.filename = child->GetAttribute("filename")->GetAsString();
    out->ignored.push_back(ignored);
  }
}

}  // namespace

WorldFileStatus readWorldFile(const std::string& path, const std::vector<std::string>& model_path,
                              const PhysicsParams& base, WorldFile* out) {
  namespace fs = std::filesystem;
  // Told apart by its type alone, never opened: a FIFO would block the reader, a device such
  // as /dev/zero would never end.
  const core::FileCheck check = core::checkRegularFile(path);
  switch (check.code) {
    case core::FileCheck::Code::Missing: return {WorldFileCode::NotFound, path};
    case core::FileCheck::Code::Unreadable: return {WorldFileCode::Unreadable, path};
    case core::FileCheck::Code::NotRegular:
      return {WorldFileCode::NotAFile, core::fileTypeName(check.type)};
    case core::FileCheck::Code::Readable: break;
  }
  std::error_code error;
  if (fs::file_size(path, error) > kMaxModelXmlBytes)
    return {WorldFileCode::TooLarge, path, double(kMaxModelXmlBytes)};
  // libsdformat says only "Unable to read file" of XML that is not well-formed (the reason goes to
  // stderr): tinyxml2 says where and what.
  tinyxml2::XMLDocument xml;
  if (xml.LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS) {
    const char* reason = xml.ErrorStr();
    return {WorldFileCode::InvalidXml, reason ? reason : "parse error"};
  }
  // libsdformat would read any other root as a URDF and say only that it has no <robot>.
  const tinyxml2::XMLElement* root_xml = xml.RootElement();
  if (root_xml && std::string(root_xml->Name()) != "sdf")
    return {WorldFileCode::NotSdf, rootDescription(*root_xml)};
  const size_t placed = placedModels(xml);
  if (placed > kMaxWorldModels)
    return {WorldFileCode::TooManyModels, std::to_string(placed), double(kMaxWorldModels)};
  core::SdfDocument document;
  {
    const std::lock_guard<std::mutex> one_parser(core::parserMutex());
    core::readSdfDocument(fs::absolute(path).string(), core::SdfSource::File, model_path,
                          &document);
  }
  if (document.includes.code == core::IncludeCheck::Code::Cycle)
    return {WorldFileCode::IncludeCycle, document.includes.subject};
  if (document.includes.code == core::IncludeCheck::Code::TooMany)
    return {WorldFileCode::TooManyIncludedModels,
            (document.includes.at_least ? "at least " : "") +
                std::to_string(document.includes.count),
            double(core::kMaxIncludedModels)};
  if (document.includes.code == core::IncludeCheck::Code::NotFound)
    return {WorldFileCode::IncludeNotFound, document.includes.subject};
  if (!document.missing.empty()) return {WorldFileCode::IncludeNotFound, document.missing.front()};
  if (!document.error.empty()) return {WorldFileCode::InvalidSdf, document.error};
  const sdf::Root& root = document.root;
  const Status version = core::checkSdfVersion(root);
  if (!version.ok()) return {WorldFileCode::InvalidSdf, version.subject};
  if (root.WorldCount() == 0) {
    const std::string root_content =
        root.Model() ? "a <model>" : root.Light() ? "a <light>" : "no <world>";
    return {WorldFileCode::NoWorld, root_content};
  }
  const sdf::World& world = *root.WorldByIndex(0);
  WorldFile file;
  file.name = world.Name();
  WorldFileStatus status = readPhysics(world, base, &file);
  if (!status.ok()) return status;
  status = readModels(world, model_path, &file);
  if (!status.ok()) return status;
  status = readState(world.Element(), &file);
  if (!status.ok()) return status;
  listIgnored(world, &file);
  *out = std::move(file);
  return {};
}

}  // namespace onedof_sim
