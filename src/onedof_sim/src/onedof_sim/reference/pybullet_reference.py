"""pybullet as the independent reference of our engines: the tutorial's robot and table loaded by
pybullet's own URDF and SDF loaders (not our model loader) and stepped by pybullet alone. The
experiments are those of the tool tutorial_scenario (bench/tutorial_scenario.cpp), which runs them
on our engines: the same arguments, the same rows.

Where pybullet's defaults differ from Gazebo's they are set to Gazebo's, and nothing else:
- every joint carries a velocity motor, which would act as a brake: switched off;
- every link gets linear and angular damping 0.04: set to 0 (joint damping stays the URDF's
  <dynamics damping>, which pybullet's loader reads itself);
- joint speed is capped at 100 rad/s: lifted;
- bodies at rest fall asleep: kept awake (Gazebo's auto_disable_bodies is false);
- inertia is computed from the collision shapes and cylinders become convex hulls: the file's
  inertia and exact cylinders are asked for;
- the SDF loader ignores <static>: a static model's base gets mass 0, which pybullet keeps in place;
- pybullet multiplies the friction of two surfaces where ODE takes the smaller: every surface gets
  1, ODE's smaller of Gazebo's ground (100) and a body (1);
- the solver: Gazebo's 50 iterations, erp 0.2, no cfm, and a contact slop of ODE's contact
  surface layer, 0.001 m; steps of 1 ms.
"""
import xml.etree.ElementTree as ElementTree

import pybullet
from pybullet_utils import bullet_client

from minimal_joint_controller.control_law import pd_torque

TIME_STEP = 0.001  # s
GRAVITY = -9.8
SOLVER_ITERATIONS = 50
ERP = 0.2
CONTACT_SLOP = 0.001  # m
FRICTION = 1.0
MAX_JOINT_VELOCITY = 1.0e6  # rad/s or m/s: no cap
CONTROL_PERIOD_STEPS = 10  # the tutorial controller's 100 Hz
JOINT = 'joint1'


class PybulletWorld:
    """One pybullet physics client: the ground plane, Gazebo's settings and the models loaded."""

    def __init__(self, contact_slop=CONTACT_SLOP):
        self.client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
        self.steps = 0
        self.client.setTimeStep(TIME_STEP)
        self.client.setGravity(0.0, 0.0, GRAVITY)
        self.client.setPhysicsEngineParameter(
            numSolverIterations=SOLVER_ITERATIONS, erp=ERP, contactERP=ERP, frictionERP=ERP,
            globalCFM=0.0, solverResidualThreshold=0.0, contactSlop=contact_slop)
        ground = self.client.createMultiBody(
            baseMass=0, baseCollisionShapeIndex=self.client.createCollisionShape(
                pybullet.GEOM_PLANE))
        self.client.changeDynamics(ground, -1, lateralFriction=FRICTION)

    def close(self):
        self.client.disconnect()

    def load_urdf(self, path, x=0.0, z=0.0):
        """The body of a URDF file with its root link frame at (x, 0, z)."""
        body = self.client.loadURDF(
            path, basePosition=(x, 0.0, z),
            flags=pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER)
        for joint in range(self.client.getNumJoints(body)):
            self.client.setJointMotorControl2(body, joint, pybullet.VELOCITY_CONTROL, force=0)
        self._set_gazebo_dynamics(body)
        return body

    def load_sdf(self, path, x=0.0):
        """The body of the one model of an SDF file, its model frame at (x, 0, 0)."""
        body, = self.client.loadSDF(path)
        if ElementTree.parse(path).findtext('model/static', 'false').strip() in ('true', '1'):
            self.client.changeDynamics(body, -1, mass=0)
        self.client.resetBasePositionAndOrientation(body, (x, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
        self._set_gazebo_dynamics(body)
        return body

    def _set_gazebo_dynamics(self, body):
        self.client.changeDynamics(body, -1,
                                   activationState=pybullet.ACTIVATION_STATE_DISABLE_SLEEPING)
        for link in range(-1, self.client.getNumJoints(body)):
            self.client.changeDynamics(body, link, linearDamping=0, angularDamping=0,
                                       lateralFriction=FRICTION,
                                       maxJointVelocity=MAX_JOINT_VELOCITY)

    def joint_index(self, body, name):
        for index in range(self.client.getNumJoints(body)):
            if self.client.getJointInfo(body, index)[1].decode() == name:
                return index
        raise ValueError('the model has no joint %s' % name)

    def joint_state(self, body, joint):
        """(position, rate); continuous joints are not wrapped."""
        return tuple(self.client.getJointState(body, joint)[:2])

    def set_joint_position(self, body, joint, position):
        self.client.resetJointState(body, joint, position, 0.0)

    def step(self, body=None, joint=None, effort=0.0):
        """One step, with `effort` on the joint for this step only (pybullet drops it after)."""
        if effort:
            self.client.setJointMotorControl2(body, joint, pybullet.TORQUE_CONTROL, force=effort)
        self.client.stepSimulation()
        self.steps += 1

    def time(self):
        """Sim time in s, to the ms as tutorial_scenario prints it."""
        return round(self.steps * TIME_STEP, 3)


def scenario(urdf, table, table_x, table_phase, kp, kv, phase_seconds, commands,
             contact_slop=CONTACT_SLOP):
    """tutorial_scenario's `scenario`: the tutorial controller's law every 10 ms of sim time (read
    q, qdot; that torque for the next 10 ms), one phase per command, each phase_seconds long; the
    table at (table_x, 0, 0) from phase table_phase (0-based) on. Rows (t, q, qdot, torque), one
    per control tick."""
    world = PybulletWorld(contact_slop)
    rows = []
    try:
        robot = world.load_urdf(urdf)
        joint = world.joint_index(robot, JOINT)
        ticks = round(phase_seconds / (CONTROL_PERIOD_STEPS * TIME_STEP))
        for phase, command in enumerate(commands):
            if phase == table_phase:
                world.load_sdf(table, table_x)
            for _ in range(ticks):
                q, qdot = world.joint_state(robot, joint)
                torque = pd_torque(command, q, qdot, kp, kv)
                rows.append((world.time(), q, qdot, torque))
                for _ in range(CONTROL_PERIOD_STEPS):
                    world.step(robot, joint, torque)
    finally:
        world.close()
    return rows


def release(urdf, z, q, effort, seconds):
    """tutorial_scenario's `release`: the robot z above the origin, joint1 at rest at q, a
    constant effort on it from the start. Rows (t, q, qdot) after every step, t = 0 first."""
    world = PybulletWorld()
    rows = []
    try:
        robot = world.load_urdf(urdf, z=z)
        joint = world.joint_index(robot, JOINT)
        world.set_joint_position(robot, joint, q)
        steps = round(seconds / TIME_STEP)
        while True:
            rows.append((world.time(),) + world.joint_state(robot, joint))
            if world.steps >= steps:
                return rows
            world.step(robot, joint, effort)
    finally:
        world.close()
