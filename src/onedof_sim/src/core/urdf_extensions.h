// What a URDF's <gazebo reference="LINK"> blocks say of a link, which urdfdom does not read and
// Gazebo's URDF conversion does: the link's Gazebo material, and the friction coefficients of
// each of its collisions (<mu1>, <mu2>, which the conversion writes into every collision's
// <surface><friction><ode>). Private to the core.
#pragma once

#include <map>
#include <optional>
#include <string>

#include "model_description.h"

namespace onedof_sim {
namespace core {

struct UrdfLinkExtension {
  std::string material;            // <material>: a Gazebo material's name; empty: none
  std::optional<double> mu1, mu2;  // as written (a negative one: unbounded, as in Gazebo)
};

// Link name -> what its <gazebo reference> blocks give; the last value given for a link wins, as
// in Gazebo's URDF conversion. XML tinyxml2 cannot read gives none (urdfdom says what is wrong
// with it). Refused, with the link and the text: a <mu1> or <mu2> that is not a number.
Status urdfLinkExtensions(const std::string& xml, std::map<std::string, UrdfLinkExtension>* out);

}  // namespace core
}  // namespace onedof_sim
