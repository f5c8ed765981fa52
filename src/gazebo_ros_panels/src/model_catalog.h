// The models Gazebo's Insert tab lists: every folder of the model path holding a model.config,
// named by that file's <name>, plus Gazebo's three simple shapes. No ROS, no Qt.
#pragma once

#include <string>
#include <vector>

namespace gazebo_ros_panels {

struct CatalogModel {
  std::string name;      // what the list shows: model.config's <name>, else the folder's name
  std::string uri_name;  // the folder's name (model://uri_name), the base of the copies' names
  std::string sdf_path;  // model.config's <sdf> file of the highest version; empty for a shape
  std::string shape;     // "box", "sphere" or "cylinder" for a simple shape, else empty
};

// The model path in the order it is searched, each folder once: the simulator's own (its
// /gazebo/model_path), then GAZEBO_MODEL_PATH's entries (':'-separated), then the packages'
// exported folders (gazebo_ros' `gazebo_model_path` exports).
std::vector<std::string> modelPathFolders(const std::vector<std::string>& simulator_path,
                                          const std::string& gazebo_model_path,
                                          const std::vector<std::string>& exported);

// Every model under `folders` (a sub-folder with a readable model.config naming an SDF file that
// exists), sorted by shown name; a folder name met again further down the path is the first
// one's (model:// resolves to the first). The three shapes come first.
std::vector<CatalogModel> listModels(const std::vector<std::string>& folders);

// The simple shapes, as Gazebo's toolbar makes them: a 1 m box, a sphere of radius 0.5, a
// cylinder of radius 0.5 and length 1, 1 kg, named unit_box, unit_sphere, unit_cylinder.
std::vector<CatalogModel> simpleShapes();

// The SDF of a simple shape (its link raised by half its height, so that inserted at z = 0 it
// rests on the ground); empty for an unknown shape.
std::string shapeSdf(const std::string& shape);

}  // namespace gazebo_ros_panels
