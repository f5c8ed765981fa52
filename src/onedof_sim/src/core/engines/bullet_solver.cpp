// The Bullet engine's solver (bullet_solver.h).
#include "bullet_solver.h"

#include "bullet_convert.h"
#include "contact_rules.h"

namespace onedof_sim {
namespace core {
namespace {

btVector3 velocityAt(const btRigidBody& body, const btVector3& point) {
  return body.getVelocityInLocalPoint(point - body.getCenterOfMassPosition());
}

}  // namespace

void BulletSolver::forget(const btTypedConstraint* constraint) { ended_.erase(constraint); }

void BulletSolver::convertContacts(btPersistentManifold** manifolds, int count,
                                   const btContactSolverInfo& info) {
  sliding_.clear();
  for (int m = 0; m < count; ++m) {
    btPersistentManifold& manifold = *manifolds[m];
    const btRigidBody* a = btRigidBody::upcast(manifold.getBody0());
    const btRigidBody* b = btRigidBody::upcast(manifold.getBody1());
    for (int p = 0; p < manifold.getNumContacts(); ++p)
      setFrictionDirections(manifold.getContactPoint(p), a, b);
  }
  btSequentialImpulseConstraintSolver::convertContacts(manifolds, count, info);
  for (int f = 0; f < m_tmpSolverContactFrictionConstraintPool.size(); ++f) {
    btSolverConstraint& friction = m_tmpSolverContactFrictionConstraintPool[f];
    const void* point =
        m_tmpSolverContactConstraintPool[friction.m_frictionIndex].m_originalContactPoint;
    if (sliding_.count(point)) friction.m_friction *= SIMDSQRT12;
  }
}

void BulletSolver::setFrictionDirections(btManifoldPoint& point, const btRigidBody* a,
                                         const btRigidBody* b) {
  const btVector3& normal = point.m_normalWorldOnB;  // from b to a
  btVector3 slip(0, 0, 0);
  if (a) slip += velocityAt(*a, point.getPositionWorldOnA());
  if (b) slip -= velocityAt(*b, point.getPositionWorldOnB());
  Vec3 in_plane;
  btVector3 first, second;
  if (slides(fromBt(slip), fromBt(normal), &in_plane)) {
    const btVector3 along = toBt(in_plane).normalized(), across = normal.cross(along);
    first = (along + across) * SIMDSQRT12;
    second = (along - across) * SIMDSQRT12;
    sliding_.insert(&point);
  } else {
    btPlaneSpace1(normal, first, second);
  }
  if (!(point.m_contactPointFlags & BT_CONTACT_FLAG_LATERAL_FRICTION_INITIALIZED) ||
      first != point.m_lateralFrictionDir1 || second != point.m_lateralFrictionDir2) {
    const btVector3 carried = point.m_appliedImpulseLateral1 * point.m_lateralFrictionDir1 +
                              point.m_appliedImpulseLateral2 * point.m_lateralFrictionDir2;
    point.m_appliedImpulseLateral1 = carried.dot(first);
    point.m_appliedImpulseLateral2 = carried.dot(second);
    point.m_lateralFrictionDir1 = first;
    point.m_lateralFrictionDir2 = second;
  }
  point.m_contactPointFlags |= BT_CONTACT_FLAG_LATERAL_FRICTION_INITIALIZED;
}

void BulletSolver::convertJoints(btTypedConstraint** constraints, int count,
                                 const btContactSolverInfo& info) {
  btSequentialImpulseConstraintSolver::convertJoints(constraints, count, info);
  if (!(info.m_solverMode & SOLVER_USE_WARMSTARTING)) return;
  int first = 0;  // the constraint's first row in the pool: rows follow the constraints' order
  for (int c = 0; c < count; ++c) {
    const int rows = m_tmpConstraintSizesPool[c].m_numConstraintRows;
    const auto last = ended_.find(constraints[c]);
    if (last != ended_.end() && last->second.step + 1 == step_ &&
        static_cast<int>(last->second.rows.size()) == rows) {
      for (int r = 0; r < rows; ++r)
        warmStart(&m_tmpSolverNonContactConstraintPool[first + r],
                  last->second.rows[r] * info.m_warmstartingFactor);
    }
    first += rows;
  }
}

// Puts `impulse` (within the row's bounds) on the row and on its two bodies, as an iteration puts
// a change of the row's impulse on them.
void BulletSolver::warmStart(btSolverConstraint* row, btScalar impulse) {
  impulse = btMax(row->m_lowerLimit, btMin(row->m_upperLimit, impulse));
  row->m_appliedImpulse = impulse;
  btSolverBody& a = m_tmpSolverBodyPool[row->m_solverBodyIdA];
  btSolverBody& b = m_tmpSolverBodyPool[row->m_solverBodyIdB];
  a.internalApplyImpulse(row->m_contactNormal1 * a.internalGetInvMass(), row->m_angularComponentA,
                         impulse);
  b.internalApplyImpulse(row->m_contactNormal2 * b.internalGetInvMass(), row->m_angularComponentB,
                         impulse);
}

btScalar BulletSolver::solveGroupCacheFriendlyIterations(
    btCollisionObject** bodies, int body_count, btPersistentManifold** manifolds,
    int manifold_count, btTypedConstraint** constraints, int constraint_count,
    const btContactSolverInfo& info, btIDebugDraw* draw) {
  const btScalar residual = btSequentialImpulseConstraintSolver::solveGroupCacheFriendlyIterations(
      bodies, body_count, manifolds, manifold_count, constraints, constraint_count, info, draw);
  for (int r = 0; r < m_tmpSolverNonContactConstraintPool.size(); ++r) {
    const btSolverConstraint& row = m_tmpSolverNonContactConstraintPool[r];
    resolveSingleConstraintRowGeneric(m_tmpSolverBodyPool[row.m_solverBodyIdA],
                                      m_tmpSolverBodyPool[row.m_solverBodyIdB], row);
  }
  return residual;
}

btScalar BulletSolver::solveGroupCacheFriendlyFinish(btCollisionObject** bodies, int count,
                                                     const btContactSolverInfo& info) {
  const void* constraint = nullptr;  // the one whose rows are being written: rows follow in order
  Ended* ended = nullptr;
  for (int r = 0; r < m_tmpSolverNonContactConstraintPool.size(); ++r) {
    const btSolverConstraint& row = m_tmpSolverNonContactConstraintPool[r];
    if (row.m_originalContactPoint != constraint) {
      constraint = row.m_originalContactPoint;
      ended = &ended_[static_cast<const btTypedConstraint*>(constraint)];
      ended->step = step_;
      ended->rows.clear();
    }
    ended->rows.push_back(row.m_appliedImpulse);
  }
  return btSequentialImpulseConstraintSolver::solveGroupCacheFriendlyFinish(bodies, count, info);
}

}  // namespace core
}  // namespace onedof_sim
