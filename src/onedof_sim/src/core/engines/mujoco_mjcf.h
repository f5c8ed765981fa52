// The MJCF text of the MuJoCo engine's models and its compile (mujoco_mjcf.cpp), for
// mujoco_engine.cpp. Private to the core.
#pragma once

#include <mujoco/mujoco.h>

#include <string>

#include "engine.h"

namespace onedof_sim {
namespace core {
namespace mjcf {

// Newton's iterations at least (PhysicsParams::sor_pgs_iters above it).
constexpr int kMinIterations = 100;

// Numbers, vectors, quaternions (w first) and a pose's pos and quat attributes, exact in text.
std::string number(double value);
std::string vector(const Vec3& v);
std::string quaternion(const Quat& q);
std::string placement(const Pose& pose);
// The model's head up to its assets: compiler, sizes (njmax constraint rows), options and the
// defaults of geoms and joints.
std::string head(const PhysicsParams& params, int njmax);
// A geom element's type and size attributes; a mesh's asset, named mesh_name, goes to *assets.
std::string geom(const ShapeSpec& shape, const std::string& mesh_name, std::string* assets);
// A body's inertial attributes (its mass and position excepted).
std::string inertia(const BodySpec& spec);
// The model compiled, or null and MuJoCo's message in *error.
mjModel* compile(const std::string& xml, std::string* error);

}  // namespace mjcf
}  // namespace core
}  // namespace onedof_sim
