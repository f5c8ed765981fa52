// The sequential-impulse (PGS) solver as the Bullet engine (bullet_engine.cpp) runs it: Bullet's
// own, with Coulomb's friction at sliding contacts, and its joints solved to the end of each step.
// Private to the core.
//
// Friction (contact_rules.h, kSlidingSpeed): each contact point's two friction directions are
// set before the solver makes its constraints. At a point sliding faster than kSlidingSpeed at
// the step's start, they are the diagonals of the slip and the direction across it, each bounded
// by mu / sqrt(2) times the normal impulse: while the point slides both are at their bounds, and
// together brake it with mu N against the slip and nothing across it. Elsewhere they are
// btPlaneSpace1's, fixed in the contact plane, as Bullet's own with
// SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION. Where a point's directions change, the
// friction impulse it carries over from the last step (warm starting) is carried over onto the
// new ones.
//
// Joints: Bullet starts each step's contact rows from the impulses they ended the last step with
// (times m_warmstartingFactor), and a joint's rows (a hinge's locking rows, its motor, its stop)
// from none; and each of its iterations solves the joints first, then the contacts and their
// friction, so that a step ends with the joints' rows as far off as the contacts' last sweep left
// them. With that, a base driven by its wheels' velocity motors at the default 50 iterations runs
// its wheels 1 % off their commanded rates and turns 2.4 % faster than commanded. Here each joint
// row starts from the impulse the same row of the same constraint ended the last step with (times
// the same factor, within the row's bounds) when the constraint has as many rows as then (a stop
// or a motor that comes or goes changes them: those rows start from none, as Bullet's), and after
// the iterations the joints' rows are swept once more: the wheels end each step at their rates,
// and the base turns within 0.4 % of its command.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <cstdint>

#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace onedof_sim {
namespace core {

class BulletSolver : public btSequentialImpulseConstraintSolver {
 public:
  // Before each step: what the joints' rows ended the step before with is what this one starts
  // from. (The world may solve its islands in more than one group a step.)
  void startStep() { ++step_; }
  // The constraint leaves the world: what it carried is dropped (a new one may get its address).
  void forget(const btTypedConstraint* constraint);

 protected:
  void convertContacts(btPersistentManifold** manifolds, int count,
                       const btContactSolverInfo& info) override;
  void convertJoints(btTypedConstraint** constraints, int count,
                     const btContactSolverInfo& info) override;
  btScalar solveGroupCacheFriendlyIterations(btCollisionObject** bodies, int body_count,
                                             btPersistentManifold** manifolds, int manifold_count,
                                             btTypedConstraint** constraints, int constraint_count,
                                             const btContactSolverInfo& info,
                                             btIDebugDraw* draw) override;
  btScalar solveGroupCacheFriendlyFinish(btCollisionObject** bodies, int count,
                                         const btContactSolverInfo& info) override;

 private:
  void setFrictionDirections(btManifoldPoint& point, const btRigidBody* a, const btRigidBody* b);
  void warmStart(btSolverConstraint* row, btScalar impulse);

  std::unordered_set<const void*> sliding_;  // this step's sliding points
  // Each constraint's rows' impulses, in row order, at the end of the step numbered `step`: read
  // by the next step before that step writes them again (a constraint is in one group a step),
  // kept from step to step so that their memory is reused.
  struct Ended {
    uint64_t step = 0;
    std::vector<btScalar> rows;
  };
  std::unordered_map<const btTypedConstraint*, Ended> ended_;
  uint64_t step_ = 0;
};

}  // namespace core
}  // namespace onedof_sim
