#include "model_catalog.h"

#include <tinyxml2.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace gazebo_ros_panels {
namespace {

// "1.10" above "1.9": versions compared number by number.
std::vector<int> versionNumbers(const std::string& version) {
  std::vector<int> numbers;
  std::istringstream parts(version);
  for (std::string part; std::getline(parts, part, '.');) {
    try {
      numbers.push_back(std::stoi(part));
    } catch (const std::exception&) {
      numbers.push_back(0);
    }
  }
  return numbers;
}

// Reads folder/model.config; false when it is missing, malformed or names no existing SDF file.
bool readModelConfig(const fs::path& folder, CatalogModel* model) {
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile((folder / "model.config").string().c_str()) != tinyxml2::XML_SUCCESS)
    return false;
  const tinyxml2::XMLElement* root = doc.FirstChildElement("model");
  if (!root) return false;
  std::vector<int> best_version;
  std::string best_file;
  for (const tinyxml2::XMLElement* sdf = root->FirstChildElement("sdf"); sdf;
       sdf = sdf->NextSiblingElement("sdf")) {
    if (!sdf->GetText()) continue;
    const char* version = sdf->Attribute("version");
    const std::vector<int> numbers = versionNumbers(version ? version : "0");
    if (best_file.empty() || numbers > best_version) {
      best_version = numbers;
      best_file = sdf->GetText();
    }
  }
  std::error_code error;
  if (best_file.empty() || !fs::is_regular_file(folder / best_file, error)) return false;
  model->uri_name = folder.filename().string();
  const tinyxml2::XMLElement* name = root->FirstChildElement("name");
  model->name = name && name->GetText() ? name->GetText() : model->uri_name;
  model->sdf_path = (folder / best_file).string();
  return true;
}

}  // namespace

std::vector<std::string> modelPathFolders(const std::vector<std::string>& simulator_path,
                                          const std::string& gazebo_model_path,
                                          const std::vector<std::string>& exported) {
  std::vector<std::string> folders;
  auto add = [&folders](const std::string& folder) {
    if (!folder.empty() && std::find(folders.begin(), folders.end(), folder) == folders.end())
      folders.push_back(folder);
  };
  for (const std::string& folder : simulator_path) add(folder);
  std::istringstream entries(gazebo_model_path);
  for (std::string folder; std::getline(entries, folder, ':');) add(folder);
  for (const std::string& folder : exported) add(folder);
  return folders;
}

std::vector<CatalogModel> simpleShapes() {
  return {{"Box", "unit_box", "", "box"},
          {"Sphere", "unit_sphere", "", "sphere"},
          {"Cylinder", "unit_cylinder", "", "cylinder"}};
}

std::vector<CatalogModel> listModels(const std::vector<std::string>& folders) {
  std::vector<CatalogModel> models;
  std::set<std::string> seen;
  for (const std::string& folder : folders) {
    std::error_code error;
    fs::directory_iterator entries(folder, error);
    if (error) continue;
    for (const fs::directory_entry& entry : entries) {
      if (!entry.is_directory(error)) continue;
      CatalogModel model;
      if (!readModelConfig(entry.path(), &model) || !seen.insert(model.uri_name).second) continue;
      models.push_back(model);
    }
  }
  std::sort(models.begin(), models.end(), [](const CatalogModel& a, const CatalogModel& b) {
    return a.name != b.name ? a.name < b.name : a.uri_name < b.uri_name;
  });
  std::vector<CatalogModel> listed = simpleShapes();
  listed.insert(listed.end(), models.begin(), models.end());
  return listed;
}

std::string shapeSdf(const std::string& shape) {
  std::string geometry;
  double half_height = 0.5;
  double ixx = 0, izz = 0;  // a solid of 1 kg
  if (shape == "box") {
    geometry = "<box><size>1 1 1</size></box>";
    ixx = izz = 1.0 / 6.0;
  } else if (shape == "sphere") {
    geometry = "<sphere><radius>0.5</radius></sphere>";
    ixx = izz = 0.1;
  } else if (shape == "cylinder") {
    geometry = "<cylinder><radius>0.5</radius><length>1</length></cylinder>";
    ixx = (3 * 0.25 + 1) / 12.0;
    izz = 0.125;
  } else {
    return "";
  }
  std::ostringstream sdf;
  sdf << "<?xml version=\"1.0\"?><sdf version=\"1.6\"><model name=\"unit_" << shape << "\">"
      << "<link name=\"link\"><pose>0 0 " << half_height << " 0 0 0</pose>"
      << "<inertial><mass>1</mass><inertia><ixx>" << ixx << "</ixx><ixy>0</ixy><ixz>0</ixz><iyy>"
      << ixx << "</iyy><iyz>0</iyz><izz>" << izz << "</izz></inertia></inertial>"
      << "<collision name=\"collision\"><geometry>" << geometry << "</geometry></collision>"
      << "<visual name=\"visual\"><geometry>" << geometry << "</geometry>"
      << "<material><script><uri>file://media/materials/scripts/gazebo.material</uri>"
      << "<name>Gazebo/Grey</name></script></material></visual>"
      << "</link></model></sdf>";
  return sdf.str();
}

}  // namespace gazebo_ros_panels
