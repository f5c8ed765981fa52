// Effort jobs and commands on joints, wrench jobs on links: the refusals, the window a job acts
// in, the bound that keeps its bodies from blowing up, and their application in each step.
#include <algorithm>
#include <cmath>

#include "world_impl.h"

namespace onedof_sim {

using namespace core;

namespace {

int64_t saturatingAdd(int64_t a, int64_t b) {
  return b > kForever - a ? kForever : a + b;
}

}  // namespace

double World::Impl::safeEffortBound(const ModelRecord& model, const JointRecord& joint) const {
  const bool prismatic = joint.desc.type == JointType::Prismatic;
  const JointFrame frame = jointFrame(model, joint);
  double inertia = 0;
  for (int body : joint.moved_bodies) {
    const BodySpec& mass = model.bodies[body];
    if (prismatic) {
      inertia += mass.mass;
      continue;
    }
    const Pose pose = model.engine_model->bodyPose(body);
    inertia += momentAbout(mass, rotate(conjugate(pose.orientation), frame.axis));
    const Vec3 arm = pose.position - frame.anchor;
    inertia += mass.mass * (dot(arm, arm) - dot(arm, frame.axis) * dot(arm, frame.axis));
  }
  const double speed = prismatic ? kMaxLinearSpeed : maxAngularSpeed(params.step);
  return inertia * speed / (kStepsToSpeedCap * params.step);
}

std::vector<JointEffortSum> World::Impl::applyJobs(int64_t t) {
  struct JointSum {
    const ModelRecord* model;
    size_t joint;
    double effort;
    int jobs;
  };
  std::vector<JointSum> sums;
  std::vector<JointEffortSum> applied;
  for (const JointEffortJob& job : joint_jobs) {
    if (job.start_ns > t || t >= job.end_ns || job.model->blown_up) continue;
    auto sum = std::find_if(sums.begin(), sums.end(), [&](const JointSum& s) {
      return s.model == job.model && s.joint == job.joint;
    });
    if (sum == sums.end()) sums.push_back({job.model, job.joint, job.effort, 1});
    else sum->effort += job.effort, ++sum->jobs;
  }
  for (const JointEffortCommand& command : joint_commands) {
    if (command.model->blown_up) continue;
    auto sum = std::find_if(sums.begin(), sums.end(), [&](const JointSum& s) {
      return s.model == command.model && s.joint == command.joint;
    });
    if (sum == sums.end()) sums.push_back({command.model, command.joint, command.effort, 1});
    else sum->effort += command.effort, ++sum->jobs;
  }
  for (const JointSum& sum : sums) {
    const JointRecord& joint = sum.model->joints[sum.joint];
    double effort = sum.effort;
    if (sum.jobs > 1) {  // a single job was clamped when it was queued
      const double bound =
          std::min(joint.desc.effort_limit, safeEffortBound(*sum.model, joint));
      if (std::abs(effort) > bound) effort = std::copysign(bound, effort);
    }
    sum.model->engine_model->addJointEffort(joint.engine_joint, effort);
    applied.push_back({sum.model, sum.joint, effort});
  }
  for (const BodyWrenchJob& job : wrench_jobs) {
    if (job.start_ns > t || t >= job.end_ns || job.model->blown_up) continue;
    Pose frame;
    Twist unused;
    if (!resolveFrame(job.reference_frame, &frame, &unused)) continue;  // reference deleted
    job.model->engine_model->addBodyWrench(job.model->links[job.link].body,
                                           rotate(frame.orientation, job.force),
                                           transformPoint(frame, job.point),
                                           rotate(frame.orientation, job.torque));
  }
  return applied;
}

void World::Impl::dropExpiredJobs(int64_t next_step_start) {
  joint_jobs.erase(std::remove_if(joint_jobs.begin(), joint_jobs.end(),
                                  [&](const JointEffortJob& j) { return j.end_ns <= next_step_start; }),
                   joint_jobs.end());
  wrench_jobs.erase(std::remove_if(wrench_jobs.begin(), wrench_jobs.end(),
                                   [&](const BodyWrenchJob& j) { return j.end_ns <= next_step_start; }),
                    wrench_jobs.end());
}

Status World::Impl::effortTarget(const std::string& joint_name, double effort, ModelRecord** model,
                                 size_t* index) const {
  if (!findJoint(joint_name, model, index)) return {StatusCode::JointNotFound, joint_name};
  if ((*model)->joints[*index].engine_joint < 0) return {StatusCode::JointIsFixed, joint_name};
  if (!std::isfinite(effort)) return {StatusCode::NotFinite, "effort"};
  return {};
}

double World::Impl::clampEffort(const ModelRecord& model, const JointRecord& joint, double effort,
                                JobOutcome* done) const {
  if (std::abs(effort) > joint.desc.effort_limit) {
    effort = std::copysign(joint.desc.effort_limit, effort);
    done->effort_limit = joint.desc.effort_limit;
  }
  const double safe = safeEffortBound(model, joint);
  if (std::abs(effort) > safe) {
    effort = std::copysign(safe, effort);
    done->safe_effort = safe;
  }
  return effort;
}

bool World::Impl::jobWindow(int64_t start_ns, int64_t duration_ns, int64_t* start, int64_t* end,
                            JobOutcome* outcome) const {
  if (duration_ns == 0) {
    outcome->queued = false;
    return false;
  }
  *start = std::max(start_ns, time_ns);
  if (duration_ns < 0) {
    *end = kForever;
  } else if (duration_ns < step_ns) {
    // [start, start + step) holds exactly one step start, wherever start falls.
    *end = *start + step_ns;
    outcome->widened_to_one_step = true;
  } else {
    *end = saturatingAdd(*start, duration_ns);
  }
  return true;
}

Status World::applyJointEffort(const std::string& joint_name, double effort, int64_t start_ns,
                               int64_t duration_ns, JobOutcome* outcome) {
  ModelRecord* model;
  size_t index;
  const Status takes = impl_->effortTarget(joint_name, effort, &model, &index);
  if (!takes.ok()) return takes;
  const JointRecord& joint = model->joints[index];
  const size_t pending = std::count_if(
      impl_->joint_jobs.begin(), impl_->joint_jobs.end(),
      [&](const JointEffortJob& job) { return job.model == model && job.joint == index; });
  if (pending >= kMaxPendingJobs) {
    Status full{StatusCode::TooManyJobs, model->name + "::" + joint.desc.name};
    full.max = kMaxPendingJobs;
    return full;
  }
  JobOutcome done;
  int64_t start = 0, end = 0;
  if (impl_->jobWindow(start_ns, duration_ns, &start, &end, &done)) {
    effort = impl_->clampEffort(*model, joint, effort, &done);
    impl_->joint_jobs.push_back({model, index, effort, start, end});
  }
  if (outcome) *outcome = done;
  return {};
}

Status World::setJointEffortCommand(const std::string& joint_name, double effort,
                                    JobOutcome* outcome) {
  ModelRecord* model;
  size_t index;
  const Status takes = impl_->effortTarget(joint_name, effort, &model, &index);
  if (!takes.ok()) return takes;
  const JointRecord& joint = model->joints[index];
  JobOutcome done;
  effort = impl_->clampEffort(*model, joint, effort, &done);
  auto& commands = impl_->joint_commands;
  auto same = std::find_if(commands.begin(), commands.end(), [&](const JointEffortCommand& c) {
    return c.model == model && c.joint == index;
  });
  if (same == commands.end()) commands.push_back({model, index, effort});
  else same->effort = effort;  // the latest command for the step replaces the earlier one
  if (outcome) *outcome = done;
  return {};
}

bool World::jointEffortActive(const std::string& joint_name, int64_t t_ns) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index)) return false;
  for (const JointEffortJob& job : impl_->joint_jobs)
    if (job.model == model && job.joint == index && job.start_ns <= t_ns && t_ns < job.end_ns)
      return true;
  return false;
}

void World::clearJointForces(const std::string& joint_name) {
  auto& jobs = impl_->joint_jobs;
  jobs.erase(std::remove_if(jobs.begin(), jobs.end(),
                            [&](const JointEffortJob& job) {
                              const std::string& bare = job.model->joints[job.joint].desc.name;
                              return bare == joint_name ||
                                     job.model->name + "::" + bare == joint_name;
                            }),
             jobs.end());
}

Status World::applyBodyWrench(const std::string& scoped_link, const std::string& reference_frame,
                              const Vec3& reference_point, const Vec3& force, const Vec3& torque,
                              int64_t start_ns, int64_t duration_ns, JobOutcome* outcome) {
  if (!isFinite(reference_point)) return {StatusCode::NotFinite, "reference_point"};
  if (!isFinite(force)) return {StatusCode::NotFinite, "force"};
  if (!isFinite(torque)) return {StatusCode::NotFinite, "torque"};
  if (!withinPosition(reference_point))
    return outOfRange("reference_point", -kMaxPosition, kMaxPosition);
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  const int body = model->links[index].body;
  if (body < 0) return {StatusCode::LinkAnchored, scoped_link};
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  const size_t pending = std::count_if(
      impl_->wrench_jobs.begin(), impl_->wrench_jobs.end(),
      [&](const BodyWrenchJob& job) { return job.model == model && job.link == index; });
  if (pending >= kMaxPendingJobs) {
    Status full{StatusCode::TooManyJobs, scoped_link};
    full.max = kMaxPendingJobs;
    return full;
  }
  JobOutcome done;
  int64_t start = 0, end = 0;
  if (impl_->jobWindow(start_ns, duration_ns, &start, &end, &done)) {
    // The same safety bound as for joint efforts, on this body alone.
    const BodySpec& mass = model->bodies[body];
    const double step = impl_->params.step;
    const double max_force = mass.mass * kMaxLinearSpeed / (kStepsToSpeedCap * step);
    const double max_torque = std::min({mass.ixx, mass.iyy, mass.izz}) * maxAngularSpeed(step) /
                              (kStepsToSpeedCap * step);
    Vec3 f = force, t = torque;
    if (norm(f) > max_force) f = (max_force / norm(f)) * f;
    if (norm(t) > max_torque) t = (max_torque / norm(t)) * t;
    if (norm(f) < norm(force) || norm(t) < norm(torque))
      done.safe_wrench = JobOutcome::WrenchBound{max_force, max_torque};
    impl_->wrench_jobs.push_back({model, index, reference_frame, reference_point, f, t, start, end});
  }
  if (outcome) *outcome = done;
  return {};
}

void World::clearBodyWrenches(const std::string& scoped_link) {
  auto& jobs = impl_->wrench_jobs;
  jobs.erase(std::remove_if(jobs.begin(), jobs.end(),
                            [&](const BodyWrenchJob& job) {
                              return job.model->name + "::" + job.model->links[job.link].desc.name ==
                                     scoped_link;
                            }),
             jobs.end());
}

}  // namespace onedof_sim
