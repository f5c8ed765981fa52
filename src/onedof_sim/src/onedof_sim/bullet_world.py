"""The pybullet physics core of onedof_sim: the same world as include/onedof_sim/world.h, free of ROS.

A test or the ROS layer (bullet_node) drives it step by step. It mirrors the ODE core's semantics
and status texts, so both engines answer the same input the same way. Not thread-safe: the owner
serialises calls.

Time is kept in integer nanoseconds so that effort-job windows (start <= t < start + duration) are
exact and never depend on floating-point rounding of step sums.

pybullet's defaults differ from Gazebo's, and are undone here:
- every joint carries a velocity motor (it would act as a brake): switched off at spawn;
- every link gets linear and angular damping 0.04: set to 0;
- URDF <dynamics damping> becomes pybullet's own joint damping (which changeDynamics cannot set to
  0): zeroed in the URDF pybullet reads, and applied explicitly as -d * qdot each step as the ODE
  core does;
- cylinders become convex hulls unless URDF_USE_IMPLICIT_CYLINDER;
- joint speed is capped at 100 rad/s: lifted;
- bullet combines the friction of two surfaces by product, ODE by min: see GROUND_FRICTION.
Torque commands and external forces last one step in pybullet, which is what the effort jobs need.
"""
import collections
import dataclasses
import enum
import math
import os
import tempfile
import xml.etree.ElementTree as ElementTree

import pybullet
from pybullet_utils import bullet_client

Vec3 = collections.namedtuple('Vec3', 'x y z', defaults=(0.0, 0.0, 0.0))
# Unit quaternion, w first (as world.h).
Quat = collections.namedtuple('Quat', 'w x y z', defaults=(1.0, 0.0, 0.0, 0.0))
Pose = collections.namedtuple('Pose', 'position orientation', defaults=(Vec3(), Quat()))
Twist = collections.namedtuple('Twist', 'linear angular', defaults=(Vec3(), Vec3()))


class Status(collections.namedtuple('Status', 'ok message')):
    """Outcome of a call that can fail on bad input: on failure the world is unchanged."""

    @classmethod
    def Ok(cls, message=''):
        return cls(True, message)

    @classmethod
    def Error(cls, message):
        return cls(False, message)


@dataclasses.dataclass
class PhysicsParams:
    """Solver settings: the fields of gazebo_msgs/ODEPhysics plus step and gravity (as world.h).

    Which of them mean something to bullet is said in _apply_params.
    """
    step: float = 0.001
    gravity: Vec3 = Vec3(0.0, 0.0, -9.8)
    quick_step: bool = False
    auto_disable_bodies: bool = False
    sor_pgs_precon_iters: int = 0
    sor_pgs_iters: int = 50
    sor_pgs_w: float = 1.3
    sor_pgs_rms_error_tol: float = 0.0
    contact_surface_layer: float = 0.001
    contact_max_correcting_vel: float = 100.0
    cfm: float = 0.0
    erp: float = 0.2
    max_contacts: int = 20


class JointType(enum.Enum):
    REVOLUTE = 'revolute'
    CONTINUOUS = 'continuous'
    PRISMATIC = 'prismatic'
    FIXED = 'fixed'


class ModelFormat(enum.Enum):
    URDF = 'urdf'
    SDF = 'sdf'


class GeometryShape(enum.Enum):
    BOX = 'box'
    CYLINDER = 'cylinder'
    SPHERE = 'sphere'
    PLANE = 'plane'


@dataclasses.dataclass
class JointInfo:
    model: str
    name: str  # bare
    type: JointType
    has_damping: bool  # the URDF declared <dynamics damping>
    damping: float
    position: float  # rad or m; continuous joints are not wrapped
    rate: float


@dataclasses.dataclass
class LinkInfo:
    model: str
    name: str  # bare
    com: Pose  # centre of mass in the link frame (orientation of the inertial frame)
    mass: float
    ixx: float
    ixy: float
    ixz: float
    iyy: float
    iyz: float
    izz: float
    gravity_mode: bool = True


@dataclasses.dataclass
class ModelInfo:
    name: str
    canonical_link: str  # scoped
    links: list  # scoped
    geoms: list  # collision names
    joints: list  # bare
    is_static: bool


@dataclasses.dataclass
class CollisionShape:
    """One collision shape in world coordinates, for visualisation."""
    model: str
    link: str
    shape: GeometryShape
    size: Vec3  # box: x y z; cylinder: radius, 0, length; sphere: radius
    pose: Pose  # world pose of the shape's centre


# Ground plane friction. Gazebo's ground has mu 100 and ODE uses the smaller mu of the two surfaces,
# so a body of mu 1 slides on the ground with mu 1. Bullet multiplies the two (capped at 10): mu 100
# here would make every contact with the ground grip 10 times harder than under ODE. With 1, the
# product equals ODE's min for every body of mu <= 100.
GROUND_FRICTION = 1.0
DEFAULT_FRICTION = 1.0
# pybullet caps joint speed at 100 rad/s by default; ODE has no cap.
MAX_JOINT_VELOCITY = 1.0e6
WORLD_FRAMES = ('', 'world')

# ------------------------------------------------------------------------------------------------
# Rigid transforms: (position (x, y, z), quaternion (x, y, z, w) as pybullet orders it).


def _quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def _quat_conj(q):
    return (-q[0], -q[1], -q[2], q[3])


def _rotate(q, v):
    x, y, z = _quat_mul(_quat_mul(q, (v[0], v[1], v[2], 0.0)), _quat_conj(q))[:3]
    return (x, y, z)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _compose(a, b):
    """The transform a * b: b expressed in a's parent frame."""
    return _add(a[0], _rotate(a[1], b[0])), _quat_mul(a[1], b[1])


def _invert(t):
    q_inv = _quat_conj(t[1])
    return tuple(-c for c in _rotate(q_inv, t[0])), q_inv


def _quat_from_rpy(roll, pitch, yaw):
    """Fixed-axis roll about x, then pitch about y, then yaw about z (URDF and SDF)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def _normalized(q):
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)


IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def _transform_from_pose(pose):
    o = pose.orientation
    return (tuple(pose.position), _normalized((o.x, o.y, o.z, o.w)))


def _pose_from_transform(t):
    (x, y, z), (qx, qy, qz, qw) = t
    return Pose(Vec3(x, y, z), Quat(qw, qx, qy, qz))


def _pose_is_finite(pose):
    values = tuple(pose.position) + tuple(pose.orientation)
    return (all(math.isfinite(v) for v in values)
            and sum(c * c for c in pose.orientation) > 1e-12)


def _twist_is_finite(twist):
    return all(math.isfinite(v) for v in tuple(twist.linear) + tuple(twist.angular))


# ------------------------------------------------------------------------------------------------
# Model descriptions parsed from URDF and SDF, before anything is built.

class ModelError(Exception):
    """Bad or unsupported model XML; the message is the status text."""


@dataclasses.dataclass
class _Collision:
    name: str
    shape: GeometryShape
    size: tuple  # as CollisionShape.size
    origin: tuple  # transform in the link frame


@dataclasses.dataclass
class _LinkSpec:
    name: str
    com: tuple = IDENTITY  # inertial frame in the link frame
    mass: float = 0.0
    inertia: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)  # ixx ixy ixz iyy iyz izz
    collisions: list = dataclasses.field(default_factory=list)
    friction: float = DEFAULT_FRICTION
    pose: tuple = IDENTITY  # SDF: in the model frame


@dataclasses.dataclass
class _JointSpec:
    name: str
    type: JointType
    parent: str
    child: str
    damping: float = None  # None: not declared
    effort_limit: float = None  # None: no limit given


@dataclasses.dataclass
class _ModelSpec:
    links: list  # _LinkSpec in tree order, root first; a URDF `world` root is not among them
    joints: list  # _JointSpec in tree order
    world_rooted: bool  # URDF root link named `world`: the model is fixed to the world
    is_static: bool
    pose: tuple = IDENTITY  # SDF <model><pose>


def _floats(text, count, what):
    try:
        values = [float(v) for v in (text or '').split()]
    except ValueError:
        raise ModelError('bad XML: %s is not %d numbers: "%s"' % (what, count, text))
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise ModelError('bad XML: %s is not %d finite numbers: "%s"' % (what, count, text))
    return values


def _number(element, attribute, what, default=None):
    text = element.get(attribute)
    if text is None:
        if default is None:
            raise ModelError('bad XML: %s has no %s' % (what, attribute))
        return default
    return _floats(text, 1, '%s %s' % (what, attribute))[0]


def _parse_xml(xml, root_tag):
    try:
        root = ElementTree.fromstring(xml)
    except ElementTree.ParseError as error:
        raise ModelError('bad XML: %s' % error)
    if root.tag != root_tag:
        raise ModelError('bad XML: the root element is <%s>, expected <%s>' % (root.tag, root_tag))
    return root


def _geometry(geometry, what):
    """(shape, size) of a <geometry> element; URDF attributes or SDF child elements."""
    if geometry is None or len(geometry) != 1:
        raise ModelError('bad XML: %s needs exactly one geometry' % what)
    shape = geometry[0]
    if shape.tag == 'box':
        text = shape.get('size') if shape.get('size') is not None else shape.findtext('size')
        size = _floats(text, 3, what + ' box size')
        if min(size) <= 0:
            raise ModelError('bad XML: %s box size must be > 0' % what)
        return GeometryShape.BOX, tuple(size)
    if shape.tag == 'cylinder':
        radius = _floats(shape.get('radius', shape.findtext('radius')), 1, what + ' radius')[0]
        length = _floats(shape.get('length', shape.findtext('length')), 1, what + ' length')[0]
        if radius <= 0 or length <= 0:
            raise ModelError('bad XML: %s cylinder radius and length must be > 0' % what)
        return GeometryShape.CYLINDER, (radius, 0.0, length)
    if shape.tag == 'sphere':
        radius = _floats(shape.get('radius', shape.findtext('radius')), 1, what + ' radius')[0]
        if radius <= 0:
            raise ModelError('bad XML: %s sphere radius must be > 0' % what)
        return GeometryShape.SPHERE, (radius, 0.0, 0.0)
    raise ModelError('unsupported content: %s geometry <%s> (box, cylinder and sphere are)'
                     % (what, shape.tag))


def _urdf_origin(element):
    origin = element.find('origin') if element is not None else None
    if origin is None:
        return IDENTITY
    xyz = _floats(origin.get('xyz', '0 0 0'), 3, 'origin xyz')
    rpy = _floats(origin.get('rpy', '0 0 0'), 3, 'origin rpy')
    return tuple(xyz), _quat_from_rpy(*rpy)


def parse_urdf(xml):
    """The _ModelSpec of a URDF document; raises ModelError."""
    robot = _parse_xml(xml, 'robot')
    links = {}
    for link in robot.findall('link'):
        name = link.get('name')
        if not name:
            raise ModelError('bad XML: a <link> has no name')
        if name in links:
            raise ModelError('bad XML: link [%s] is declared twice' % name)
        spec = _LinkSpec(name)
        inertial = link.find('inertial')
        if inertial is not None:
            spec.com = _urdf_origin(inertial)
            mass = inertial.find('mass')
            spec.mass = _number(mass, 'value', 'link [%s] mass' % name) if mass is not None else 0.0
            inertia = inertial.find('inertia')
            if inertia is not None:
                spec.inertia = tuple(_number(inertia, key, 'link [%s] inertia' % name, 0.0)
                                     for key in ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz'))
            if spec.mass < 0:
                raise ModelError('bad XML: link [%s] has a negative mass' % name)
        for index, collision in enumerate(link.findall('collision')):
            what = 'link [%s] collision' % name
            shape, size = _geometry(collision.find('geometry'), what)
            spec.collisions.append(_Collision(collision.get('name') or '%s_collision_%d'
                                              % (name, index), shape, size,
                                              _urdf_origin(collision)))
        links[name] = spec
    if not links:
        raise ModelError('bad XML: the robot has no link')

    joints = {}
    children = collections.defaultdict(list)
    parent_of = {}
    for joint in robot.findall('joint'):
        name = joint.get('name')
        if not name:
            raise ModelError('bad XML: a <joint> has no name')
        if name in joints:
            raise ModelError('bad XML: joint [%s] is declared twice' % name)
        try:
            joint_type = JointType(joint.get('type'))
        except ValueError:
            raise ModelError('unsupported content: joint [%s] of type "%s" (revolute, continuous, '
                             'prismatic and fixed are)' % (name, joint.get('type')))
        parent = (joint.find('parent') if joint.find('parent') is not None
                  else ElementTree.Element('parent')).get('link')
        child = (joint.find('child') if joint.find('child') is not None
                 else ElementTree.Element('child')).get('link')
        for role, link in (('parent', parent), ('child', child)):
            if link not in links:
                raise ModelError('bad XML: joint [%s] %s link [%s] does not exist'
                                 % (name, role, link))
        if child in parent_of:
            raise ModelError('bad XML: link [%s] is the child of two joints' % child)
        spec = _JointSpec(name, joint_type, parent, child)
        dynamics = joint.find('dynamics')
        if dynamics is not None and dynamics.get('damping') is not None:
            spec.damping = _number(dynamics, 'damping', 'joint [%s] damping' % name)
            if spec.damping < 0:
                raise ModelError('bad XML: joint [%s] has a negative damping' % name)
        limit = joint.find('limit')
        if limit is not None and limit.get('effort') is not None:
            spec.effort_limit = abs(_number(limit, 'effort', 'joint [%s] limit' % name))
        joints[name] = spec
        parent_of[child] = name
        children[parent].append(spec)

    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        raise ModelError('bad XML: the links form %s' % ('a loop' if not roots else
                                                       'no single tree (roots %s)' % roots))
    ordered_links, ordered_joints = [], []
    pending = [roots[0]]
    while pending:
        name = pending.pop(0)
        ordered_links.append(links[name])
        for joint in children[name]:
            ordered_joints.append(joint)
            pending.append(joint.child)
    if len(ordered_links) != len(links):
        raise ModelError('bad XML: the links form a loop')
    world_rooted = roots[0] == 'world'
    if world_rooted:
        ordered_links.pop(0)
    if not ordered_links:
        raise ModelError('bad XML: the robot has no link besides world')
    return _ModelSpec(ordered_links, ordered_joints, world_rooted, is_static=False)


def _sdf_pose(element):
    pose = element.find('pose') if element is not None else None
    if pose is None:
        return IDENTITY
    if pose.get('relative_to'):
        raise ModelError('unsupported content: <pose relative_to>')
    x, y, z, roll, pitch, yaw = _floats(pose.text, 6, 'pose')
    return (x, y, z), _quat_from_rpy(roll, pitch, yaw)


def parse_sdf(xml):
    """The _ModelSpec of an SDF document with one model; raises ModelError.

    Supported: static models of any number of links, and dynamic models of one link (a free body),
    with box, cylinder and sphere collisions.
    """
    sdf = _parse_xml(xml, 'sdf')
    models = sdf.findall('model')
    if len(models) != 1:
        raise ModelError('bad XML: the SDF must hold exactly one <model>, it holds %d'
                         % len(models))
    model = models[0]
    for tag in ('include', 'joint', 'model'):
        if model.find(tag) is not None:
            raise ModelError('unsupported content: <%s> in an SDF model' % tag)
    is_static = (model.findtext('static') or 'false').strip() in ('true', '1')
    links = []
    for link in model.findall('link'):
        name = link.get('name')
        if not name:
            raise ModelError('bad XML: a <link> has no name')
        if any(other.name == name for other in links):
            raise ModelError('bad XML: link [%s] is declared twice' % name)
        spec = _LinkSpec(name, pose=_sdf_pose(link))
        inertial = link.find('inertial')
        if inertial is not None:
            spec.com = _sdf_pose(inertial)
            spec.mass = _floats(inertial.findtext('mass', '1'), 1, 'link [%s] mass' % name)[0]
            inertia = inertial.find('inertia')
            spec.inertia = tuple(
                _floats(inertia.findtext(key, '0') if inertia is not None else '0', 1,
                        'link [%s] %s' % (name, key))[0]
                for key in ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz'))
            if spec.mass <= 0:
                raise ModelError('bad XML: link [%s] mass must be > 0' % name)
            if any(spec.inertia[i] for i in (1, 2, 4)) and not is_static:
                raise ModelError('unsupported content: link [%s] has products of inertia (give '
                                 'the inertia in its principal axes)' % name)
        elif not is_static:
            # SDF's defaults for a link without <inertial>.
            spec.mass, spec.inertia = 1.0, (1.0, 0.0, 0.0, 1.0, 0.0, 1.0)
        for index, collision in enumerate(link.findall('collision')):
            what = 'link [%s] collision' % name
            shape, size = _geometry(collision.find('geometry'), what)
            spec.collisions.append(_Collision(collision.get('name') or '%s_collision_%d'
                                              % (name, index), shape, size,
                                              _sdf_pose(collision)))
            mu = collision.findtext('surface/friction/ode/mu')
            if mu is not None:
                spec.friction = _floats(mu, 1, what + ' mu')[0]
        links.append(spec)
    if not links:
        raise ModelError('bad XML: the model has no link')
    if not is_static and len(links) > 1:
        raise ModelError('unsupported content: a dynamic SDF model of %d links (one link, or '
                         'static; use URDF for articulated models)' % len(links))
    return _ModelSpec(links, [], world_rooted=False, is_static=is_static, pose=_sdf_pose(model))


# ------------------------------------------------------------------------------------------------
# The world.

@dataclasses.dataclass
class _Joint:
    model: str
    spec: _JointSpec
    index: int  # pybullet joint index (== index of its child link)


@dataclasses.dataclass
class _Model:
    name: str
    spec: _ModelSpec
    body: int  # pybullet body id
    link_index: dict  # link name -> pybullet link index (-1: base)
    joints: dict  # joint name -> _Joint, tree order
    base_to_model: tuple  # the model frame in the base link frame
    base_inertial: tuple  # the base inertial frame in the base link frame (pybullet's base pose)
    spawn_pose: tuple  # model frame in the world at spawn


@dataclasses.dataclass
class _Job:
    """An effort job on a joint, or a wrench job on a link; end_ns None: until cleared."""
    model: str
    target: str  # bare joint name, or bare link name
    start_ns: int
    end_ns: int
    effort: float = 0.0
    force: tuple = (0.0, 0.0, 0.0)  # world frame
    torque: tuple = (0.0, 0.0, 0.0)  # world frame
    point: tuple = (0.0, 0.0, 0.0)  # in the link frame


def step_ns_of(step):
    return int(round(step * 1e9))


class BulletWorld:
    """A world of rigid-body models over pybullet, one physics client per world."""

    def __init__(self, params=None):
        self._client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
        self._params = PhysicsParams()
        self._time_ns = 0
        self._step_count = 0
        self._models = collections.OrderedDict()
        self._joint_jobs = []
        self._wrench_jobs = []
        self._ground = self._client.createMultiBody(
            baseMass=0, baseCollisionShapeIndex=self._client.createCollisionShape(
                pybullet.GEOM_PLANE))
        self._client.changeDynamics(self._ground, -1, lateralFriction=GROUND_FRICTION)
        status = self.set_params(params or PhysicsParams())
        if not status.ok:
            raise ValueError(status.message)

    def close(self):
        """Ends the physics client; the world is unusable afterwards."""
        if self._client is not None:
            self._client.disconnect()
            self._client = None

    # --- time and stepping --------------------------------------------------------------------

    def step(self):
        """Advances one step: applies the jobs covering the step's start time, integrates."""
        now = self._time_ns
        torques = collections.defaultdict(float)
        for job in self._joint_jobs:
            if job.start_ns <= now and (job.end_ns is None or now < job.end_ns):
                torques[(job.model, job.target)] += job.effort
        for model in self._models.values():
            for joint in model.joints.values():
                if joint.spec.damping:
                    rate = self._client.getJointState(model.body, joint.index)[1]
                    torques[(model.name, joint.spec.name)] -= joint.spec.damping * rate
        for (model_name, joint_name), torque in torques.items():
            model = self._models[model_name]
            self._client.setJointMotorControl2(model.body, model.joints[joint_name].index,
                                               pybullet.TORQUE_CONTROL, force=torque)
        for job in self._wrench_jobs:
            if job.start_ns <= now and (job.end_ns is None or now < job.end_ns):
                model = self._models[job.model]
                link = model.link_index[job.target]
                frame = self._link_frame(model, link)
                point = _compose(frame, (job.point, IDENTITY[1]))[0]
                self._client.applyExternalForce(model.body, link, job.force, point,
                                                pybullet.WORLD_FRAME)
                self._client.applyExternalTorque(model.body, link, job.torque,
                                                 pybullet.WORLD_FRAME)
        self._client.stepSimulation()
        self._time_ns += step_ns_of(self._params.step)
        self._step_count += 1
        self._joint_jobs = [j for j in self._joint_jobs
                            if j.end_ns is None or j.end_ns > self._time_ns]
        self._wrench_jobs = [j for j in self._wrench_jobs
                             if j.end_ns is None or j.end_ns > self._time_ns]

    @property
    def time_ns(self):
        return self._time_ns

    @property
    def time(self):
        return self._time_ns * 1e-9

    @property
    def step_count(self):
        return self._step_count

    @property
    def params(self):
        return dataclasses.replace(self._params)

    def set_params(self, params):
        """Refuses non-finite numbers, step <= 0, negative iteration counts: world unchanged."""
        reals = {'time_step': params.step, 'sor_pgs_w': params.sor_pgs_w,
                 'sor_pgs_rms_error_tol': params.sor_pgs_rms_error_tol,
                 'contact_surface_layer': params.contact_surface_layer,
                 'contact_max_correcting_vel': params.contact_max_correcting_vel,
                 'cfm': params.cfm, 'erp': params.erp}
        for name, value in reals.items():
            if not math.isfinite(value):
                return Status.Error('%s is not a finite number' % name)
        if not all(math.isfinite(g) for g in params.gravity):
            return Status.Error('gravity is not finite')
        if params.step <= 0:
            return Status.Error('time_step must be > 0')
        if step_ns_of(params.step) <= 0:
            return Status.Error('time_step must be at least 1 ns')
        for name in ('sor_pgs_precon_iters', 'sor_pgs_iters', 'max_contacts'):
            if getattr(params, name) < 0:
                return Status.Error('%s must be >= 0' % name)
        self._params = dataclasses.replace(params, gravity=Vec3(*params.gravity))
        self._apply_params()
        return Status.Ok()

    def _apply_params(self):
        params = self._params
        self._client.setTimeStep(params.step)
        self._client.setGravity(*params.gravity)
        # Fields with a bullet counterpart. ODE's erp applies to joints and contacts alike;
        # rms_error_tol is the residual at which the solver may stop early (0: run every
        # iteration); contact_surface_layer is the penetration allowed without correction.
        # Not meaningful in bullet, kept and echoed only: quick_step (bullet has one solver),
        # sor_pgs_precon_iters, sor_pgs_w (not exposed by pybullet), contact_max_correcting_vel,
        # max_contacts (bullet keeps at most 4 points per body pair).
        self._client.setPhysicsEngineParameter(
            numSolverIterations=max(1, params.sor_pgs_iters), erp=params.erp,
            contactERP=params.erp, frictionERP=params.erp, globalCFM=params.cfm,
            solverResidualThreshold=params.sor_pgs_rms_error_tol,
            contactSlop=params.contact_surface_layer)
        for model in self._models.values():
            self._set_sleeping(model.body)

    def _set_sleeping(self, body):
        state = (pybullet.ACTIVATION_STATE_ENABLE_SLEEPING if self._params.auto_disable_bodies
                 else pybullet.ACTIVATION_STATE_DISABLE_SLEEPING)
        self._client.changeDynamics(body, -1, activationState=state)

    # --- models -------------------------------------------------------------------------------

    def spawn(self, name, xml, model_format, pose, reference_frame=''):
        """Builds a model from URDF or SDF with its model frame at pose in reference_frame."""
        if not name:
            return Status.Error('Failure - model name is empty')
        if name in self._models:
            return Status.Error('Failure - entity [%s] already exists' % name)
        if not _pose_is_finite(pose):
            return Status.Error('Failure - the initial pose is not finite')
        frame = self._entity_frame(reference_frame)
        if frame is None:
            return Status.Error('Failure - reference frame [%s] not found' % reference_frame)
        try:
            spec = parse_urdf(xml) if model_format == ModelFormat.URDF else parse_sdf(xml)
        except ModelError as error:
            return Status.Error('Failure - %s' % error)
        model_pose = _compose(_compose(frame[0], _transform_from_pose(pose)), spec.pose)
        try:
            model = (self._build_urdf(name, xml, spec, model_pose)
                     if model_format == ModelFormat.URDF else
                     self._build_sdf(name, spec, model_pose))
        except pybullet.error as error:
            return Status.Error('Failure - bullet could not build the model: %s' % error)
        self._models[name] = model
        self._set_sleeping(model.body)
        return Status.Ok('Successfully spawned entity')

    def _build_urdf(self, name, xml, spec, model_pose):
        robot = ElementTree.fromstring(xml)
        for dynamics in robot.iter('dynamics'):
            if 'damping' in dynamics.attrib:
                dynamics.set('damping', '0')  # pybullet refuses an empty <dynamics>
        with tempfile.NamedTemporaryFile('wb', suffix='.urdf', delete=False) as urdf_file:
            urdf_file.write(ElementTree.tostring(robot))
        try:
            body = self._client.loadURDF(
                urdf_file.name, basePosition=model_pose[0], baseOrientation=model_pose[1],
                useFixedBase=spec.world_rooted,
                flags=(pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER
                       | pybullet.URDF_MAINTAIN_LINK_ORDER))
        finally:
            os.unlink(urdf_file.name)
        link_index = {self._client.getBodyInfo(body)[0].decode(): -1}
        joints = {}
        joint_specs = {joint.name: joint for joint in spec.joints}
        for index in range(self._client.getNumJoints(body)):
            info = self._client.getJointInfo(body, index)
            joint_name, link_name = info[1].decode(), info[12].decode()
            link_index[link_name] = index
            joints[joint_name] = _Joint(name, joint_specs[joint_name], index)
            self._client.setJointMotorControl2(body, index, pybullet.VELOCITY_CONTROL, force=0)
        for index in link_index.values():
            self._client.changeDynamics(body, index, linearDamping=0, angularDamping=0,
                                        lateralFriction=DEFAULT_FRICTION,
                                        maxJointVelocity=MAX_JOINT_VELOCITY)
        base_inertial = (tuple(self._client.getDynamicsInfo(body, -1)[3]),
                         tuple(self._client.getDynamicsInfo(body, -1)[4]))
        ordered = collections.OrderedDict((j.name, joints[j.name]) for j in spec.joints)
        return _Model(name, spec, body, link_index, ordered, IDENTITY, base_inertial, model_pose)

    def _build_sdf(self, name, spec, model_pose):
        shapes = []
        for link in spec.links:
            shapes.append(self._compound_shape(link.collisions))
        base = spec.links[0]
        if spec.is_static:
            masses, inertial = [0.0] * len(spec.links), IDENTITY
        else:
            masses, inertial = [base.mass], base.com
        body = self._client.createMultiBody(
            baseMass=masses[0], baseCollisionShapeIndex=shapes[0],
            basePosition=_compose(model_pose, base.pose)[0],
            baseOrientation=_compose(model_pose, base.pose)[1],
            baseInertialFramePosition=inertial[0], baseInertialFrameOrientation=inertial[1],
            linkMasses=masses[1:], linkCollisionShapeIndices=shapes[1:],
            linkVisualShapeIndices=[-1] * (len(spec.links) - 1),
            linkPositions=[_compose(_invert(base.pose), link.pose)[0] for link in spec.links[1:]],
            linkOrientations=[_compose(_invert(base.pose), link.pose)[1]
                              for link in spec.links[1:]],
            linkInertialFramePositions=[(0, 0, 0)] * (len(spec.links) - 1),
            linkInertialFrameOrientations=[(0, 0, 0, 1)] * (len(spec.links) - 1),
            linkParentIndices=[0] * (len(spec.links) - 1),
            linkJointTypes=[pybullet.JOINT_FIXED] * (len(spec.links) - 1),
            linkJointAxis=[(0, 0, 1)] * (len(spec.links) - 1))
        link_index = {link.name: index - 1 for index, link in enumerate(spec.links)}
        for link in spec.links:
            self._client.changeDynamics(body, link_index[link.name], linearDamping=0,
                                        angularDamping=0, lateralFriction=link.friction)
        if not spec.is_static:
            ixx, _, _, iyy, _, izz = base.inertia
            self._client.changeDynamics(body, -1, localInertiaDiagonal=(ixx, iyy, izz))
        base_inertial = (tuple(self._client.getDynamicsInfo(body, -1)[3]),
                         tuple(self._client.getDynamicsInfo(body, -1)[4]))
        return _Model(name, spec, body, link_index, collections.OrderedDict(),
                      _invert(base.pose), base_inertial, model_pose)

    def _compound_shape(self, collisions):
        if not collisions:
            return -1
        kwargs = {'shapeTypes': [], 'halfExtents': [], 'radii': [], 'lengths': [],
                  'collisionFramePositions': [], 'collisionFrameOrientations': []}
        for collision in collisions:
            size = collision.size
            kwargs['shapeTypes'].append({GeometryShape.BOX: pybullet.GEOM_BOX,
                                         GeometryShape.CYLINDER: pybullet.GEOM_CYLINDER,
                                         GeometryShape.SPHERE: pybullet.GEOM_SPHERE}[collision.shape])
            kwargs['halfExtents'].append([s / 2 for s in size] if collision.shape ==
                                         GeometryShape.BOX else [0, 0, 0])
            kwargs['radii'].append(size[0])
            kwargs['lengths'].append(size[2])
            kwargs['collisionFramePositions'].append(collision.origin[0])
            kwargs['collisionFrameOrientations'].append(collision.origin[1])
        return self._client.createCollisionShapeArray(**kwargs)

    def delete_model(self, name):
        model = self._models.get(name)
        if model is None:
            return Status.Error('model does not exist')
        self._client.removeBody(model.body)
        del self._models[name]
        self._joint_jobs = [j for j in self._joint_jobs if j.model != name]
        self._wrench_jobs = [j for j in self._wrench_jobs if j.model != name]
        return Status.Ok('successfully deleted model')

    def model_names(self):
        return list(self._models)

    def has_model(self, name):
        return name in self._models

    def model_properties(self, name):
        """(Status, ModelInfo or None)."""
        model = self._models.get(name)
        if model is None:
            return Status.Error('model does not exist'), None
        links = model.spec.links
        return Status.Ok('got properties'), ModelInfo(
            name=name, canonical_link='%s::%s' % (name, links[0].name),
            links=['%s::%s' % (name, link.name) for link in links],
            geoms=[c.name for link in links for c in link.collisions],
            joints=list(model.joints), is_static=model.spec.is_static)

    def model_state(self, name, reference_frame=''):
        """(Status, Pose, Twist) of the model frame in reference_frame."""
        model = self._models.get(name)
        if model is None:
            return Status.Error('model does not exist'), None, None
        state = self._frame_state(model, -1, model.base_to_model)
        return self._relative_state(state, reference_frame)

    def set_model_state(self, name, pose, twist, reference_frame=''):
        model = self._models.get(name)
        if model is None:
            return Status.Error('model does not exist')
        return self._set_base_state(model, model.base_to_model, pose, twist, reference_frame)

    def set_model_configuration(self, name, joints, positions):
        """Sets joint positions with zero velocity, moving the links below each joint."""
        model = self._models.get(name)
        if model is None:
            return Status.Error('model does not exist')
        if len(joints) != len(positions):
            return Status.Error('joint_names and joint_positions differ in length (%d and %d)'
                                % (len(joints), len(positions)))
        for joint, position in zip(joints, positions):
            if joint not in model.joints:
                return Status.Error('joint [%s] not found in model [%s]' % (joint, name))
            if model.joints[joint].spec.type == JointType.FIXED:
                return Status.Error('joint [%s] is fixed' % joint)
            if not math.isfinite(position):
                return Status.Error('position of joint [%s] is not finite' % joint)
        for joint, position in zip(joints, positions):
            self._client.resetJointState(model.body, model.joints[joint].index, position, 0.0)
        return Status.Ok('success')

    # --- links --------------------------------------------------------------------------------

    def _find_link(self, scoped_link):
        model_name, _, link_name = scoped_link.partition('::')
        model = self._models.get(model_name)
        if model is None or not link_name or link_name not in model.link_index:
            return None, None
        if model.spec.world_rooted and link_name == 'world':
            return None, None
        return model, link_name

    def link_properties(self, scoped_link):
        """(Status, LinkInfo or None)."""
        model, link_name = self._find_link(scoped_link)
        if model is None:
            return Status.Error(LINK_NOT_FOUND), None
        spec = next(link for link in model.spec.links if link.name == link_name)
        return Status.Ok('got properties'), LinkInfo(
            model.name, link_name, _pose_from_transform(spec.com), spec.mass, *spec.inertia,
            gravity_mode=True)

    def link_state(self, scoped_link, reference_frame=''):
        """(Status, Pose, Twist) of the link frame in reference_frame."""
        model, link_name = self._find_link(scoped_link)
        if model is None:
            return Status.Error(LINK_NOT_FOUND), None, None
        state = self._frame_state(model, model.link_index[link_name], IDENTITY)
        return self._relative_state(state, reference_frame)

    def set_link_state(self, scoped_link, pose, twist, reference_frame=''):
        """Moves a model's base link, or a link welded to it by fixed joints, with the model.

        Bullet articulations keep every other link on its joint, so those are refused.
        """
        model, link_name = self._find_link(scoped_link)
        if model is None:
            return Status.Error(LINK_NOT_FOUND)
        base_to_link = self._welded_to_base(model, link_name)
        if base_to_link is None:
            return Status.Error('link [%s] moves on a joint: the bullet engine sets the state of '
                                'a model\'s root link only' % scoped_link)
        return self._set_base_state(model, base_to_link, pose, twist, reference_frame)

    def link_names(self):
        return ['%s::%s' % (model.name, link.name) for model in self._models.values()
                for link in model.spec.links]

    # --- joints -------------------------------------------------------------------------------

    def _find_joint(self, joint):
        model_name, scoped, joint_name = joint.rpartition('::')
        for model in self._models.values():
            if scoped and model.name != model_name:
                continue
            if joint_name in model.joints:
                return model, model.joints[joint_name]
        return None, None

    def joint_info(self, joint):
        """(Status, JointInfo or None)."""
        model, found = self._find_joint(joint)
        if model is None:
            return Status.Error('joint not found'), None
        position, rate = 0.0, 0.0
        if found.spec.type != JointType.FIXED:
            position, rate = self._client.getJointState(model.body, found.index)[:2]
        return Status.Ok('got properties'), JointInfo(
            model.name, found.spec.name, found.spec.type, found.spec.damping is not None,
            found.spec.damping or 0.0, position, rate)

    def apply_joint_effort(self, joint, effort, start_ns, duration_ns):
        """Queues an effort job; see world.h for the window rules."""
        model, found = self._find_joint(joint)
        if model is None:
            return Status.Error('joint not found')
        if not math.isfinite(effort):
            return Status.Error('effort is not a finite number')
        status, window = self._job_window(start_ns, duration_ns)
        if window is None:
            return status
        limit = found.spec.effort_limit
        clamped = limit is not None and abs(effort) > limit
        if clamped:
            effort = math.copysign(limit, effort)
        self._joint_jobs.append(_Job(model.name, found.spec.name, *window, effort=effort))
        message = status.message
        if clamped:
            message += ' (clamped to the effort limit %g)' % limit
        return Status.Ok(message)

    def clear_joint_forces(self, joint):
        """Drops every pending job on joints of that bare name (any model)."""
        self._joint_jobs = [j for j in self._joint_jobs if j.target != joint]

    def apply_body_wrench(self, scoped_link, reference_frame, reference_point, force, torque,
                          start_ns, duration_ns):
        """Wrench on a link, force applied at reference_point; force, torque and point in
        reference_frame, fixed in the world at the time of the call (as Gazebo)."""
        model, link_name = self._find_link(scoped_link)
        if model is None:
            return Status.Error(BODY_NOT_FOUND)
        values = tuple(reference_point) + tuple(force) + tuple(torque)
        if not all(math.isfinite(v) for v in values):
            return Status.Error('wrench or reference point is not finite')
        frame = self._entity_frame(reference_frame)
        if frame is None:
            return Status.Error('reference frame [%s] not found' % reference_frame)
        status, window = self._job_window(start_ns, duration_ns)
        if window is None:
            return status
        frame = frame[0]
        link_frame = self._link_frame(model, model.link_index[link_name])
        point_world = _compose(frame, (tuple(reference_point), IDENTITY[1]))[0]
        point_in_link = _compose(_invert(link_frame), (point_world, IDENTITY[1]))[0]
        self._wrench_jobs.append(_Job(model.name, link_name, *window,
                                      force=_rotate(frame[1], tuple(force)),
                                      torque=_rotate(frame[1], tuple(torque)),
                                      point=point_in_link))
        return Status.Ok(status.message.replace('effort', 'wrench'))

    def clear_body_wrenches(self, scoped_link):
        model_name, _, link_name = scoped_link.partition('::')
        self._wrench_jobs = [j for j in self._wrench_jobs
                             if (j.model, j.target) != (model_name, link_name)]

    def _job_window(self, start_ns, duration_ns):
        """(Status, (start_ns, end_ns) or None): the half-open window of a job."""
        step_ns = step_ns_of(self._params.step)
        start_ns = max(int(start_ns), self._time_ns)
        if duration_ns == 0:
            return Status.Ok('duration is 0: nothing to apply'), None
        if duration_ns < 0:
            return Status.Ok('effort set'), (start_ns, None)
        if duration_ns < step_ns:
            return (Status.Ok('effort set (the duration is shorter than a step: applied for '
                              'exactly one step)'), (start_ns, start_ns + step_ns))
        return Status.Ok('effort set'), (start_ns, start_ns + int(duration_ns))

    # --- reset --------------------------------------------------------------------------------

    def reset_world(self):
        """Every model back to its spawn pose and configuration, zero velocity; drops jobs."""
        for model in self._models.values():
            base = _compose(model.spawn_pose, _invert(model.base_to_model))
            inertial = _compose(base, model.base_inertial)
            self._client.resetBasePositionAndOrientation(model.body, *inertial)
            self._client.resetBaseVelocity(model.body, (0, 0, 0), (0, 0, 0))
            for joint in model.joints.values():
                if joint.spec.type != JointType.FIXED:
                    self._client.resetJointState(model.body, joint.index, 0.0, 0.0)
        self._joint_jobs = []
        self._wrench_jobs = []

    def reset_simulation(self):
        self.reset_world()
        self._time_ns = 0

    # --- introspection ------------------------------------------------------------------------

    def collision_shapes(self):
        shapes = [CollisionShape('ground_plane', 'link', GeometryShape.PLANE, Vec3(),
                                 _pose_from_transform(IDENTITY))]
        for model in self._models.values():
            for link in model.spec.links:
                frame = self._link_frame(model, model.link_index[link.name])
                for collision in link.collisions:
                    shapes.append(CollisionShape(
                        model.name, link.name, collision.shape, Vec3(*collision.size),
                        _pose_from_transform(_compose(frame, collision.origin))))
        return shapes

    # --- frames -------------------------------------------------------------------------------

    def _link_frame(self, model, index):
        """World transform of a link frame (pybullet index, -1: base)."""
        if index == -1:
            inertial = self._client.getBasePositionAndOrientation(model.body)
            return _compose(inertial, _invert(model.base_inertial))
        state = self._client.getLinkState(model.body, index, computeForwardKinematics=True)
        return tuple(state[4]), tuple(state[5])

    def _frame_state(self, model, index, offset):
        """(transform, linear velocity, angular velocity) in the world of the frame `offset`
        fixed in a link: the velocity is that of the frame's origin."""
        if index == -1:
            com = self._client.getBasePositionAndOrientation(model.body)[0]
            linear, angular = self._client.getBaseVelocity(model.body)
        else:
            state = self._client.getLinkState(model.body, index, computeLinkVelocity=True,
                                              computeForwardKinematics=True)
            com, linear, angular = state[0], state[6], state[7]
        frame = _compose(self._link_frame(model, index), offset)
        linear = _add(linear, _cross(angular, _sub(frame[0], com)))
        return frame, tuple(linear), tuple(angular)

    def _entity_frame(self, entity):
        """(transform, linear, angular) of "" / "world", a model, or "model::link"; None: unknown."""
        if entity in WORLD_FRAMES:
            return IDENTITY, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        if entity in self._models:
            model = self._models[entity]
            return self._frame_state(model, -1, model.base_to_model)
        model, link_name = self._find_link(entity)
        if model is None:
            return None
        return self._frame_state(model, model.link_index[link_name], IDENTITY)

    def _relative_state(self, state, reference_frame):
        reference = self._entity_frame(reference_frame)
        if reference is None:
            return (Status.Error('reference frame [%s] not found' % reference_frame), None, None)
        (frame, linear, angular), (ref, ref_linear, ref_angular) = state, reference
        # As Gazebo: pose relative to the reference, velocity differences in its orientation.
        inverse = _invert(ref)
        pose = _compose(inverse, frame)
        linear = _rotate(inverse[1], _sub(linear, ref_linear))
        angular = _rotate(inverse[1], _sub(angular, ref_angular))
        return (Status.Ok('got state'), _pose_from_transform(pose),
                Twist(Vec3(*linear), Vec3(*angular)))

    def _welded_to_base(self, model, link_name):
        """The transform base link frame -> link frame if only fixed joints lie between them."""
        parent_joint = {joint.spec.child: joint for joint in model.joints.values()}
        name = link_name
        while name in parent_joint:
            if parent_joint[name].spec.type != JointType.FIXED:
                return None
            name = parent_joint[name].spec.parent
        # Welded: the current transform is the constant one.
        return _compose(_invert(self._link_frame(model, -1)),
                        self._link_frame(model, model.link_index[link_name]))

    def _set_base_state(self, model, base_to_frame, pose, twist, reference_frame):
        """Moves the model so that the frame base_to_frame (fixed in the base link) reaches pose
        and twist in reference_frame."""
        if not _pose_is_finite(pose) or not _twist_is_finite(twist):
            return Status.Error('pose or twist is not finite')
        reference = self._entity_frame(reference_frame)
        if reference is None:
            return Status.Error('reference frame [%s] not found' % reference_frame)
        ref, ref_linear, ref_angular = reference
        frame = _compose(ref, _transform_from_pose(pose))
        linear = _add(_rotate(ref[1], tuple(twist.linear)), ref_linear)
        angular = _add(_rotate(ref[1], tuple(twist.angular)), ref_angular)
        inertial = _compose(_compose(frame, _invert(base_to_frame)), model.base_inertial)
        self._client.resetBasePositionAndOrientation(model.body, *inertial)
        # pybullet's base velocity is that of the centre of mass.
        com_linear = _add(linear, _cross(angular, _sub(inertial[0], frame[0])))
        self._client.resetBaseVelocity(model.body, com_linear, angular)
        return Status.Ok('set model state')


LINK_NOT_FOUND = 'link not found, did you forget to scope the link by model name?'
BODY_NOT_FOUND = 'body not found, did you forget to scope the body by model name?'

