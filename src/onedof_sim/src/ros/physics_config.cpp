#include "physics_config.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "node_options.h"

namespace onedof_sim {
namespace {

// One parameter of PhysicsConfig, in gazebo_ros' order, with the range a dynamic_reconfigure
// server clamps to: gazebo_ros' range, narrowed where World refuses more (erp, sor_pgs_iters,
// sor_pgs_rms_error_tol, max_contacts).
struct PhysicsField {
  const char* name;
  const char* type;  // "double", "bool" or "int"
  const char* description;
  double min, max;
  double (*get)(const PhysicsSettings&);
  void (*set)(PhysicsSettings*, double);
};

// clang-format off
const PhysicsField kPhysicsFields[] = {
  {"time_step", "double", "physics step, s", 0, 10,
   [](const PhysicsSettings& s) { return s.params.step; },
   [](PhysicsSettings* s, double v) { s->params.step = v; }},
  {"max_update_rate", "double", "steps per wall second; 0 = as fast as possible", 0, kMaxPacedRate,
   [](const PhysicsSettings& s) { return s.max_update_rate; },
   [](PhysicsSettings* s, double v) { s->max_update_rate = v; }},
  {"gravity_x", "double", "gravity along x, m/s^2", -100, 100,
   [](const PhysicsSettings& s) { return s.params.gravity.x; },
   [](PhysicsSettings* s, double v) { s->params.gravity.x = v; }},
  {"gravity_y", "double", "gravity along y, m/s^2", -100, 100,
   [](const PhysicsSettings& s) { return s.params.gravity.y; },
   [](PhysicsSettings* s, double v) { s->params.gravity.y = v; }},
  {"gravity_z", "double", "gravity along z, m/s^2", -100, 100,
   [](const PhysicsSettings& s) { return s.params.gravity.z; },
   [](PhysicsSettings* s, double v) { s->params.gravity.z = v; }},
  {"auto_disable_bodies", "bool", "let bodies at rest sleep (ODE)", 0, 1,
   [](const PhysicsSettings& s) { return s.params.auto_disable_bodies ? 1.0 : 0.0; },
   [](PhysicsSettings* s, double v) { s->params.auto_disable_bodies = v != 0; }},
  {"sor_pgs_precon_iters", "int", "preconditioning iterations of the SOR PGS solver", 0, 10000,
   [](const PhysicsSettings& s) { return double(s.params.sor_pgs_precon_iters); },
   [](PhysicsSettings* s, double v) { s->params.sor_pgs_precon_iters = uint32_t(v); }},
  {"sor_pgs_iters", "int", "iterations of the SOR PGS solver", 1, 10000,
   [](const PhysicsSettings& s) { return double(s.params.sor_pgs_iters); },
   [](PhysicsSettings* s, double v) { s->params.sor_pgs_iters = uint32_t(v); }},
  {"sor_pgs_w", "double", "SOR relaxation of the PGS solver", 0, 5,
   [](const PhysicsSettings& s) { return s.params.sor_pgs_w; },
   [](PhysicsSettings* s, double v) { s->params.sor_pgs_w = v; }},
  {"sor_pgs_rms_error_tol", "double", "RMS error tolerance of the SOR PGS solver", 0, 10000,
   [](const PhysicsSettings& s) { return s.params.sor_pgs_rms_error_tol; },
   [](PhysicsSettings* s, double v) { s->params.sor_pgs_rms_error_tol = v; }},
  {"cfm", "double", "constraint force mixing", 0, 10,
   [](const PhysicsSettings& s) { return s.params.cfm; },
   [](PhysicsSettings* s, double v) { s->params.cfm = v; }},
  {"erp", "double", "error reduction parameter", 0, 1,
   [](const PhysicsSettings& s) { return s.params.erp; },
   [](PhysicsSettings* s, double v) { s->params.erp = v; }},
  {"contact_surface_layer", "double", "penetration allowed before contacts push back, m", 0, 10,
   [](const PhysicsSettings& s) { return s.params.contact_surface_layer; },
   [](PhysicsSettings* s, double v) { s->params.contact_surface_layer = v; }},
  {"contact_max_correcting_vel", "double", "fastest a contact corrects penetration, m/s", 0, 1e7,
   [](const PhysicsSettings& s) { return s.params.contact_max_correcting_vel; },
   [](PhysicsSettings* s, double v) { s->params.contact_max_correcting_vel = v; }},
  {"max_contacts", "int", "most contact points between two geoms", 0, 65535,
   [](const PhysicsSettings& s) { return double(s.params.max_contacts); },
   [](PhysicsSettings* s, double v) { s->params.max_contacts = uint32_t(v); }},
};
// clang-format on

constexpr int kDefaultGroupId = 0;  // dynamic_reconfigure's top-level group, "Default"

// The value a Reconfigure request gives the field, if it names it (in the list of its type, as
// dynamic_reconfigure's own servers read it), clamped to the field's range as they clamp.
std::optional<double> requested(const dynamic_reconfigure::Config& config,
                                const PhysicsField& field) {
  std::optional<double> value;
  for (const auto& p : config.doubles)
    if (p.name == field.name && std::string(field.type) == "double") value = p.value;
  for (const auto& p : config.ints)
    if (p.name == field.name && std::string(field.type) == "int") value = p.value;
  for (const auto& p : config.bools)
    if (p.name == field.name && std::string(field.type) == "bool") value = p.value ? 1 : 0;
  if (value && !std::isnan(*value)) value = std::clamp(*value, field.min, field.max);
  return value;
}

}  // namespace

dynamic_reconfigure::Config toConfig(const PhysicsSettings& settings) {
  dynamic_reconfigure::Config config;
  for (const PhysicsField& field : kPhysicsFields) {
    const double value = field.get(settings);
    if (std::string(field.type) == "bool") {
      dynamic_reconfigure::BoolParameter p;
      p.name = field.name;
      p.value = value != 0;
      config.bools.push_back(p);
    } else if (std::string(field.type) == "int") {
      dynamic_reconfigure::IntParameter p;
      p.name = field.name;
      p.value = static_cast<int32_t>(value);
      config.ints.push_back(p);
    } else {
      dynamic_reconfigure::DoubleParameter p;
      p.name = field.name;
      p.value = value;
      config.doubles.push_back(p);
    }
  }
  dynamic_reconfigure::GroupState group;
  group.name = "Default";
  group.state = true;
  group.id = group.parent = kDefaultGroupId;
  config.groups.push_back(group);
  return config;
}

void applyRequested(const dynamic_reconfigure::Config& request, PhysicsSettings* settings) {
  for (const PhysicsField& field : kPhysicsFields)
    if (const std::optional<double> value = requested(request, field)) field.set(settings, *value);
}

dynamic_reconfigure::ConfigDescription physicsDescription(const PhysicsSettings& defaults) {
  dynamic_reconfigure::ConfigDescription description;
  dynamic_reconfigure::Group group;
  group.name = "Default";
  group.id = group.parent = kDefaultGroupId;
  PhysicsSettings min, max;
  for (const PhysicsField& field : kPhysicsFields) {
    dynamic_reconfigure::ParamDescription param;
    param.name = field.name;
    param.type = field.type;
    param.level = 1;
    param.description = field.description;
    group.parameters.push_back(param);
    field.set(&min, field.min);
    field.set(&max, field.max);
  }
  description.groups.push_back(group);
  description.min = toConfig(min);
  description.max = toConfig(max);
  description.dflt = toConfig(defaults);
  return description;
}

}  // namespace onedof_sim
