// The checks of what World is given (physics parameters, poses, states) against the Limits, and
// the Status formatting for logs and test failures.
#include <cmath>
#include <ostream>

#include "world_impl.h"

namespace onedof_sim {
namespace core {

bool isFinite(const Twist& t) { return onedof_sim::isFinite(t.linear) && onedof_sim::isFinite(t.angular); }

Status outOfRange(std::string field, double min, double max) {
  Status status{StatusCode::OutOfRange, std::move(field)};
  status.min = min;
  status.max = max;
  return status;
}

Status validateParams(const PhysicsParams& p) {
  using Field = std::pair<const char*, double>;
  const Field numbers[] = {{"step", p.step},
                           {"gravity", p.gravity.x},
                           {"gravity", p.gravity.y},
                           {"gravity", p.gravity.z},
                           {"sor_pgs_w", p.sor_pgs_w},
                           {"sor_pgs_rms_error_tol", p.sor_pgs_rms_error_tol},
                           {"contact_surface_layer", p.contact_surface_layer},
                           {"contact_max_correcting_vel", p.contact_max_correcting_vel},
                           {"cfm", p.cfm},
                           {"erp", p.erp}};
  for (const auto& [field, value] : numbers)
    if (!std::isfinite(value)) return {StatusCode::NotFinite, field};
  struct Range {
    const char* field;
    double value, min, max;
  };
  // Besides the step (kMinStep), gazebo_ros' own ranges (its dynamic_reconfigure Physics.cfg),
  // narrowed where a value means nothing: erp is a fraction of the error corrected per step; SOR
  // converges only for a relaxation in (0, 2) and barely moves below 0.01; a step runs every
  // solver iteration, so a billion of them would freeze the world; ODE's dCollide takes the
  // contact count in 16 bits. Gravity: 10 g, beyond any planet a robot works on. cfm 10 already
  // makes every constraint a soft spring; 1e308 makes the solver's matrix infinite.
  const Range ranges[] = {
      {"step", p.step, kMinStep, kMaxStep},
      {"gravity", p.gravity.x, -100, 100},
      {"gravity", p.gravity.y, -100, 100},
      {"gravity", p.gravity.z, -100, 100},
      {"erp", p.erp, 0, 1},
      {"cfm", p.cfm, 0, 10},
      {"contact_surface_layer", p.contact_surface_layer, 0, 10},
      {"contact_max_correcting_vel", p.contact_max_correcting_vel, 0, 1e7},
      {"sor_pgs_w", p.sor_pgs_w, 0.01, 5},
      {"sor_pgs_rms_error_tol", p.sor_pgs_rms_error_tol, 0, 1e4},
      {"sor_pgs_iters", double(p.sor_pgs_iters), 1, 1e4},
      {"sor_pgs_precon_iters", double(p.sor_pgs_precon_iters), 0, 1e4},
      {"max_contacts", double(p.max_contacts), 0, 0xffff}};
  for (const Range& range : ranges)
    if (!(range.value >= range.min && range.value <= range.max))
      return outOfRange(range.field, range.min, range.max);
  return {};
}

bool withinPosition(const Vec3& v) {
  return std::abs(v.x) <= kMaxPosition && std::abs(v.y) <= kMaxPosition &&
         std::abs(v.z) <= kMaxPosition;
}

Status checkPose(const Pose& pose) {
  if (!onedof_sim::isFinite(pose)) return {StatusCode::NotFinite, "pose"};
  const double norm = quatNorm(pose.orientation);
  if (!std::isfinite(norm)) return {StatusCode::QuaternionOverflow, "pose"};
  if (norm < 1e-9) return {StatusCode::ZeroQuaternion, "pose"};
  if (!withinPosition(pose.position))
    return outOfRange("pose.position", -kMaxPosition, kMaxPosition);
  return {};
}

Status checkState(const Pose& pose, const Twist& twist, double step) {
  const Status status = checkPose(pose);
  if (!status.ok()) return status;
  if (!isFinite(twist)) return {StatusCode::NotFinite, "twist"};
  if (norm(twist.linear) > kMaxLinearSpeed) return outOfRange("twist.linear", 0, kMaxLinearSpeed);
  if (norm(twist.angular) > maxAngularSpeed(step))
    return outOfRange("twist.angular", 0, maxAngularSpeed(step));
  return {};
}

}  // namespace core

std::ostream& operator<<(std::ostream& out, StatusCode code) {
  switch (code) {
    case StatusCode::Ok: return out << "Ok";
    case StatusCode::ModelNotFound: return out << "ModelNotFound";
    case StatusCode::LinkNotFound: return out << "LinkNotFound";
    case StatusCode::CollisionNotFound: return out << "CollisionNotFound";
    case StatusCode::JointNotFound: return out << "JointNotFound";
    case StatusCode::ReferenceFrameNotFound: return out << "ReferenceFrameNotFound";
    case StatusCode::ModelExists: return out << "ModelExists";
    case StatusCode::EmptyModelName: return out << "EmptyModelName";
    case StatusCode::NotFinite: return out << "NotFinite";
    case StatusCode::ZeroQuaternion: return out << "ZeroQuaternion";
    case StatusCode::QuaternionOverflow: return out << "QuaternionOverflow";
    case StatusCode::ModelRejected: return out << "ModelRejected";
    case StatusCode::JointIsFixed: return out << "JointIsFixed";
    case StatusCode::LinkAnchored: return out << "LinkAnchored";
    case StatusCode::LengthMismatch: return out << "LengthMismatch";
    case StatusCode::InvalidParameter: return out << "InvalidParameter";
    case StatusCode::OutOfRange: return out << "OutOfRange";
    case StatusCode::InvalidModelName: return out << "InvalidModelName";
    case StatusCode::TooManyJobs: return out << "TooManyJobs";
    case StatusCode::EngineFault: return out << "EngineFault";
    case StatusCode::EngineFaultUnattributed: return out << "EngineFaultUnattributed";
  }
  return out << "StatusCode(" << static_cast<int>(code) << ")";
}

std::ostream& operator<<(std::ostream& out, const Status& status) {
  out << status.code;
  if (!status.subject.empty()) out << " '" << status.subject << "'";
  if (status.code == StatusCode::OutOfRange) out << " [" << status.min << ", " << status.max << "]";
  if (status.code == StatusCode::TooManyJobs) out << " (at most " << status.max << ")";
  return out;
}

}  // namespace onedof_sim
