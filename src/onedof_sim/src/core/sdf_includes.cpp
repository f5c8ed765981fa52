// An SDF document's <include>s followed through the files they name, before libsdformat reads
// it (sdf_parsing.h, checkIncludes).
#include <tinyxml2.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>

#include "expansion_graph.h"
#include "mesh_loader.h"
#include "onedof_sim/trim.h"
#include "regular_file.h"
#include "sdf_parsing.h"

namespace onedof_sim {
namespace core {
namespace {

namespace fs = std::filesystem;

// "1.7" as {1, 7}; {0, 0} for text that is no version.
std::pair<int, int> versionOf(const char* text) {
  std::istringstream in(text ? text : "");
  int major = 0, minor = 0;
  char dot = 0;
  if (!(in >> major >> dot >> minor) || dot != '.') return {0, 0};
  return {major, minor};
}

// The SDF file of a model folder as libsdformat picks it: its model.config's <sdf> of the
// newest version libsdformat reads (the first <sdf> without one), or model.sdf without a
// model.config. Empty when there is none, and when its model.config is there but no readable
// regular file (libsdformat would open it, and a FIFO would hold it).
fs::path modelFile(const fs::path& folder) {
  const fs::path config = folder / "model.config";
  const FileCheck config_check = checkRegularFile(config);
  if (config_check.code == FileCheck::Code::Missing) return folder / "model.sdf";
  if (!config_check.readable()) return {};
  tinyxml2::XMLDocument document;
  if (document.LoadFile(config.c_str()) != tinyxml2::XML_SUCCESS) return {};
  const tinyxml2::XMLElement* model = document.FirstChildElement("model");
  const tinyxml2::XMLElement* best = model ? model->FirstChildElement("sdf") : nullptr;
  if (!best) return {};
  const std::pair<int, int> newest = versionOf(sdf::SDF::Version().c_str());
  for (const tinyxml2::XMLElement* e = best->NextSiblingElement("sdf"); e;
       e = e->NextSiblingElement("sdf")) {
    const std::pair<int, int> version = versionOf(e->Attribute("version"));
    if (version > versionOf(best->Attribute("version")) && version <= newest) best = e;
  }
  return folder / trimmed(best->GetText());
}

// The file an <include>'s <uri> names, as libsdformat finds it: model://NAME/... in the first
// folder of the model path that has it, a file:// or absolute path as it is, a relative one from
// the including file's folder.
struct IncludedFile {
  fs::path file;         // empty: found nowhere (libsdformat says so itself), or refused
  // Refused as found nowhere: a model:// path that climbs out of the model path once normalised,
  // or a file (or its folder's model.config) that is there but no readable regular file.
  bool refused = false;
};
IncludedFile includedFile(const std::string& uri, const std::vector<std::string>& model_path,
                          const fs::path& folder) {
  std::error_code ignored;
  std::vector<fs::path> candidates;
  const std::string model_scheme = "model://", file_scheme = "file://";
  if (uri.rfind(model_scheme, 0) == 0) {
    if (!staysInside(uri.substr(model_scheme.size()))) return {{}, true};
    for (const std::string& root : model_path)
      candidates.push_back(fs::path(root) / uri.substr(model_scheme.size()));
  } else if (uri.rfind(file_scheme, 0) == 0) {
    candidates.push_back(uri.substr(file_scheme.size()));
  } else if (fs::path(uri).is_absolute()) {
    candidates.push_back(uri);
  } else {
    candidates.push_back(folder / uri);
    candidates.push_back(uri);
  }
  for (const fs::path& candidate : candidates) {
    if (!fs::exists(candidate, ignored)) continue;
    const fs::path file = fs::is_directory(candidate, ignored) ? modelFile(candidate) : candidate;
    if (file.empty() || !checkRegularFile(file).readable()) return {{}, true};
    return {fs::weakly_canonical(file, ignored), false};
  }
  return {};
}

// The <uri>s of a document's <include>s, in document order; a plugin's own elements are not
// SDF's and are skipped.
std::vector<std::string> includeUris(const tinyxml2::XMLElement& root) {
  std::vector<std::string> uris;
  std::vector<const tinyxml2::XMLElement*> pending{&root};
  while (!pending.empty()) {
    const tinyxml2::XMLElement* e = pending.back();
    pending.pop_back();
    if (std::strcmp(e->Name(), "plugin") == 0) continue;
    if (std::strcmp(e->Name(), "include") == 0) {
      if (const tinyxml2::XMLElement* uri = e->FirstChildElement("uri"))
        uris.push_back(trimmed(uri->GetText()));
      continue;
    }
    for (const tinyxml2::XMLElement* child = e->LastChildElement(); child;
         child = child->PreviousSiblingElement())
      pending.push_back(child);
  }
  return uris;
}

}  // namespace

IncludeCheck checkIncludes(const std::string& source, SdfSource kind,
                           const std::vector<std::string>& model_path, size_t max_models) {
  // Node 0 the document, then each file its includes reach, read once however often included.
  ExpansionGraph graph;
  std::vector<std::string> names{kind == SdfSource::File ? source : "the document"};
  std::map<fs::path, size_t> index;
  std::error_code ignored;
  if (kind == SdfSource::File) index.emplace(fs::weakly_canonical(source, ignored), 0);
  const auto node = [&](const fs::path& file) {
    auto found = index.find(file);
    if (found != index.end()) return found->second;
    index.emplace(file, names.size());
    names.push_back(file.string());
    return names.size() - 1;
  };
  IncludeCheck check;
  for (size_t next = 0; next < names.size(); ++next) {
    // More files than models: the includes place more models than accepted, whatever else.
    if (names.size() > max_models + 1) {
      check.code = IncludeCheck::Code::TooMany;
      check.count = names.size() - 1;
      check.at_least = true;
      return check;
    }
    tinyxml2::XMLDocument document;
    const bool read = next == 0 && kind == SdfSource::String
                          ? document.Parse(source.c_str(), source.size()) == tinyxml2::XML_SUCCESS
                          : document.LoadFile(names[next].c_str()) == tinyxml2::XML_SUCCESS;
    graph.edges.emplace_back();
    graph.own.push_back({0, 0});
    if (!read || !document.RootElement()) continue;  // libsdformat says why
    const fs::path folder = next == 0 && kind == SdfSource::String
                                ? fs::path()
                                : fs::path(names[next]).parent_path();
    for (const std::string& uri : includeUris(*document.RootElement())) {
      // Confined to the model path as a mesh's model:// is, and read only if a regular file:
      // one refused is said to be found nowhere, in the words of a missing one, before
      // libsdformat opens anything.
      const IncludedFile included = includedFile(uri, model_path, folder);
      if (included.refused) {
        check.code = IncludeCheck::Code::NotFound;
        check.subject = uri;
        return check;
      }
      graph.own[next][0] = saturatingAdd(graph.own[next][0], 1);
      if (!included.file.empty()) graph.edges[next].push_back(node(included.file));
    }
  }
  const Expansion expansion = expand(graph);
  if (!expansion.cycle.empty()) {
    check.code = IncludeCheck::Code::Cycle;
    for (size_t file : expansion.cycle)
      check.subject += (check.subject.empty() ? "" : " -> ") + names[file];
    return check;
  }
  check.count = expansion.totals[0][0];
  if (check.count > max_models) check.code = IncludeCheck::Code::TooMany;
  return check;
}

}  // namespace core
}  // namespace onedof_sim
