// Reading an SDF document as Gazebo classic reads it (sdf_parsing.h, readSdfDocument).
#include <bitset>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include <tinyxml2.h>

#include "model_description.h"
#include "sdf_parsing.h"

namespace onedof_sim {
namespace core {
namespace {

// libsdformat 12 checks two things Gazebo 11's libsdformat (9) did not, and refuses the whole
// document for either: a value outside the bounds its schema gives (a negative friction
// coefficient, which Gazebo reads as unbounded friction), and an element of a required value left
// empty (a contact sensor's <collision name="..."/> of SDF 1.3), which libsdformat 9 left at its
// default. The schema's descriptions lose both here, before the document is read against them.
// An <include>d file and a nested model are read against a schema of their own, which keeps them.
void relaxAsLibsdformat9(const sdf::ElementPtr& description, std::set<const sdf::Element*>* seen) {
  if (!description || !seen->insert(description.get()).second) return;
  if (const sdf::ParamPtr value = description->GetValue())
    description->AddValue(value->GetTypeName(), value->GetDefaultAsString(), false, "", "",
                          value->GetDescription());
  for (size_t i = 0; i < description->GetElementDescriptionCount(); ++i)
    relaxAsLibsdformat9(description->GetElementDescription(i), seen);
}

// Whether a DOM error is one this simulator refuses a document for: two models, links or joints
// of one name would make scoped names ambiguous, and the DOM keeps only the first.
bool refusedDomError(const sdf::Error& error) {
  return error.Code() == sdf::ErrorCode::DUPLICATE_NAME;
}

// libsdformat says why it cannot read XML that is not well-formed only on stderr: tinyxml2 says
// where and what.
std::string whyUnread(const std::string& source, SdfSource kind) {
  tinyxml2::XMLDocument xml;
  const tinyxml2::XMLError parsed = kind == SdfSource::File
                                        ? xml.LoadFile(source.c_str())
                                        : xml.Parse(source.c_str(), source.size());
  if (parsed != tinyxml2::XML_SUCCESS && xml.ErrorStr())
    return std::string("not well-formed XML: ") + xml.ErrorStr();
  return "libsdformat cannot read it";
}

// The schema every document is read against: libsdformat's, relaxed as libsdformat 9's, built
// once (sdf::init parses the whole schema, several times the cost of reading a model against
// it). Under parserMutex(), as its readers.
const sdf::ElementPtr& relaxedSchema() {
  static const sdf::ElementPtr schema = [] {
    sdf::SDFPtr built(new sdf::SDF());
    sdf::init(built);
    std::set<const sdf::Element*> seen;
    relaxAsLibsdformat9(built->Root(), &seen);
    return built->Root();
  }();
  return schema;
}

// Elements of the schema that a document without one reads the same without their descriptions:
// optional, holding no value of their own, never added by libsdformat's reader unless the
// document has them, and loaded by its DOM only as the elements the document has
// (loadUniqueRepeated), or not at all. Reading copies into each element it makes the description
// of that element with every description below it (sdf::Element::Clone): these are about 1,000
// of the 1,300 elements and attributes of a <model>'s (its links' sensors, its joints), which a
// world of plain models copies for every model and again for every link.
constexpr const char* kPrunable[] = {"sensor",   "joint",        "light",      "particle_emitter",
                                     "projector", "audio_source", "audio_sink", "battery",
                                     "gripper"};
using Prunable = std::bitset<std::size(kPrunable)>;

// The kPrunable names the document's text never opens an element of ("<sensor" nowhere): a
// comment or a longer name that starts so keeps the description.
Prunable absentFrom(const std::string& text) {
  Prunable absent;
  for (size_t i = 0; i < std::size(kPrunable); ++i)
    absent[i] = text.find(std::string("<") + kPrunable[i]) == std::string::npos;
  return absent;
}

// A description's own part, without the descriptions below it: its name, its kind (required,
// copy_children, a reference to another), its text, its attributes and its value.
sdf::ElementPtr copyOwnPart(const sdf::ElementPtr& description) {
  sdf::ElementPtr copy(new sdf::Element);
  copy->SetName(description->GetName());
  copy->SetRequired(description->GetRequired());
  copy->SetCopyChildren(description->GetCopyChildren());
  copy->SetReferenceSDF(description->ReferenceSDF());
  copy->SetDescription(description->GetDescription());
  for (size_t i = 0; i < description->GetAttributeCount(); ++i) {
    const sdf::ParamPtr attribute = description->GetAttribute(i);
    copy->AddAttribute(attribute->GetKey(), attribute->GetTypeName(),
                       attribute->GetDefaultAsString(), attribute->GetRequired(),
                       attribute->GetDescription());
  }
  if (const sdf::ParamPtr value = description->GetValue())
    copy->AddValue(value->GetTypeName(), value->GetDefaultAsString(), value->GetRequired(),
                   value->GetMinValueAsString().value_or(""),
                   value->GetMaxValueAsString().value_or(""), value->GetDescription());
  return copy;
}

// A copy of a description and those below it, without those named in `without` that are optional
// and hold no value.
sdf::ElementPtr copyWithout(const sdf::ElementPtr& description,
                            const std::set<std::string>& without) {
  sdf::ElementPtr copy = copyOwnPart(description);
  for (size_t i = 0; i < description->GetElementDescriptionCount(); ++i) {
    const sdf::ElementPtr child = description->GetElementDescription(i);
    const bool prunable = child->GetRequired() != "1" && !child->GetValue();
    if (!(prunable && without.count(child->GetName())))
      copy->AddElementDescription(copyWithout(child, without));
  }
  return copy;
}

// The relaxed schema without the descriptions of the kPrunable elements absent from a document.
// Each such schema is built once (a few milliseconds) and kept, up to kKeptSchemas of them; past
// that one is built for the document and freed with it. Called, as all reading, under
// parserMutex (sdf_parsing.h): the kept schemas need no lock of their own.
sdf::ElementPtr schemaFor(const std::string& text) {
  constexpr size_t kKeptSchemas = 16;
  static std::map<unsigned long, sdf::ElementPtr> kept;
  const Prunable absent = absentFrom(text);
  if (absent.none()) return relaxedSchema();
  const auto found = kept.find(absent.to_ulong());
  if (found != kept.end()) return found->second;
  std::set<std::string> without;
  for (size_t i = 0; i < std::size(kPrunable); ++i)
    if (absent[i]) without.insert(kPrunable[i]);
  sdf::ElementPtr schema = copyWithout(relaxedSchema(), without);
  if (kept.size() < kKeptSchemas) kept.emplace(absent.to_ulong(), schema);
  return schema;
}

// The document's text: the source itself, or the file's content (empty when it cannot be read;
// the reader then says why).
std::string documentText(const std::string& source, SdfSource kind) {
  if (kind == SdfSource::String) return source;
  std::ifstream file(source, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

// A root <sdf> element for one document to fill: the schema's root's own part, its element
// descriptions shared with the schema, not copied. Reading only copies a description into
// each element it makes (sdf::Element::Clone), so the shared ones stay as they are; a copy of the
// root's would cost a copy of the whole schema for each document.
sdf::ElementPtr documentRoot(const sdf::ElementPtr& schema) {
  sdf::ElementPtr root = copyOwnPart(schema);
  for (size_t i = 0; i < schema->GetElementDescriptionCount(); ++i)
    root->AddElementDescription(schema->GetElementDescription(i));
  return root;
}

}  // namespace

void readSdfDocument(const std::string& source, SdfSource kind,
                     const std::vector<std::string>& model_path, SdfDocument* out) {
  out->includes = checkIncludes(source, kind, model_path, kMaxIncludedModels);
  if (!out->includes.ok()) return;
  out->elements.reset(new sdf::SDF());
  out->elements->Root(documentRoot(schemaFor(documentText(source, kind))));
  const sdf::ParserConfig config = modelPathConfig(model_path, &out->missing);
  sdf::Errors errors;
  bool read = false;
  try {
    read = kind == SdfSource::File ? sdf::readFile(source, config, out->elements, errors)
                                   : sdf::readString(source, config, out->elements, errors);
  } catch (const std::exception& e) {
    // libsdformat 12 throws std::invalid_argument ("stoi") on a version like "abc".
    out->error = e.what();
    return;
  }
  if (!out->missing.empty()) return;
  if (!read || !errors.empty()) {
    out->error = errors.empty() ? whyUnread(source, kind) : joinErrors(errors);
    return;
  }
  sdf::Errors refused;
  for (const sdf::Error& error : out->root.Load(out->elements, config))
    if (refusedDomError(error)) refused.push_back(error);
  if (!refused.empty()) out->error = joinErrors(refused);
}

}  // namespace core
}  // namespace onedof_sim
