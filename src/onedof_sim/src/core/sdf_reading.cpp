// Reading an SDF document as Gazebo classic reads it (sdf_parsing.h, readSdfDocument).
#include <set>

#include <tinyxml2.h>

#include "sdf_parsing.h"

namespace onedof_sim {
namespace core {
namespace {

// libsdformat 12's schema bounds Gazebo's friction coefficients below by 0 and refuses the whole
// document for a negative one; Gazebo 11's libsdformat had no bounds, and Gazebo reads a negative
// coefficient as unbounded friction. The schema's descriptions of those elements lose their
// bounds here, before the document is read against them.
void unboundFrictionCoefficients(const sdf::ElementPtr& description, const std::string& parent,
                                 std::set<const sdf::Element*>* seen) {
  if (!description || !seen->insert(description.get()).second) return;
  static const std::set<std::string> kCoefficients = {"mu", "mu2", "friction", "friction2"};
  const sdf::ParamPtr value = description->GetValue();
  if ((parent == "ode" || parent == "bullet") && kCoefficients.count(description->GetName()) &&
      value)
    description->AddValue(value->GetTypeName(), value->GetDefaultAsString(), value->GetRequired(),
                          "", "", value->GetDescription());
  for (size_t i = 0; i < description->GetElementDescriptionCount(); ++i)
    unboundFrictionCoefficients(description->GetElementDescription(i), description->GetName(),
                                seen);
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

}  // namespace

void readSdfDocument(const std::string& source, SdfSource kind,
                     const std::vector<std::string>& model_path, SdfDocument* out) {
  out->elements.reset(new sdf::SDF());
  sdf::init(out->elements);
  std::set<const sdf::Element*> seen;
  unboundFrictionCoefficients(out->elements->Root(), "", &seen);
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
