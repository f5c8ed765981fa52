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

from onedof_sim.transforms import (add, compose, cross, invert, normalized, quaternion_conjugate,
                                   quaternion_from_rpy, quaternion_multiply, rotate, sub)

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

IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def _transform_from_pose(pose):
    o = pose.orientation
    return (tuple(pose.position), normalized((o.x, o.y, o.z, o.w)))


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
# Model descriptions parsed from URDF and SDF, before anything is built. Every message below is
# the ODE core's (src/core/model_loader.cpp and world.cpp), so both engines refuse alike; only
# the parser's own detail after "invalid URDF: " / "invalid SDF: " differs.

class ModelError(Exception):
    """Bad or unsupported model XML; the message is the status text after "SpawnModel: "."""


class _SyntaxError(ModelError):
    """Malformed content that the ODE core's parsers (urdfdom, libsdformat) reject."""


@dataclasses.dataclass
class _Collision:
    name: str
    shape: GeometryShape
    size: tuple  # as CollisionShape.size
    origin: tuple  # transform in the link frame


@dataclasses.dataclass
class _LinkSpec:
    name: str
    has_inertial: bool = False
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
    has_damping: bool = False
    damping: float = 0.0
    effort_limit: float = math.inf


@dataclasses.dataclass
class _ModelSpec:
    links: list  # _LinkSpec parents first (depth first); a URDF `world` root is not among them
    joints: list  # _JointSpec in the same order
    world_rooted: bool  # URDF root link named `world`: the model is fixed to the world
    is_static: bool


def _floats(text, count, what):
    try:
        values = [float(v) for v in (text or '').split()]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise _SyntaxError('%s is not %d finite numbers: "%s"' % (what, count, text))
    return values


def _attribute(element, attribute, what, default=None):
    text = element.get(attribute)
    if text is None:
        if default is None:
            raise _SyntaxError('%s has no %s' % (what, attribute))
        return default
    return _floats(text, 1, '%s %s' % (what, attribute))[0]


def _parse_xml(xml, root_tag):
    try:
        root = ElementTree.fromstring(xml)
    except ElementTree.ParseError as error:
        raise _SyntaxError(str(error))
    if root.tag != root_tag:
        raise _SyntaxError('the root element is <%s>, expected <%s>' % (root.tag, root_tag))
    return root


def _collision_name(given, link, index):
    """Gazebo's URDF conversion names unnamed collisions this way (as the ODE core)."""
    if given:
        return given
    return link + '_collision' + ('' if index == 0 else '_%d' % index)


def _geometry(collision, link, name):
    """(shape, size) of a collision's <geometry>: URDF attributes or SDF child elements."""
    geometry = collision.find('geometry')
    if geometry is None or len(geometry) == 0:
        raise ModelError("collision of link '%s' has no geometry" % link)
    shape = geometry[0]

    def value(key):
        text = shape.get(key) if shape.get(key) is not None else shape.findtext(key)
        return _floats(text, 3 if key == 'size' else 1, "link '%s' %s %s" % (link, shape.tag, key))

    if shape.tag == 'box':
        kind, size = GeometryShape.BOX, tuple(value('size'))
        ok = min(size) > 0
    elif shape.tag == 'cylinder':
        kind, size = GeometryShape.CYLINDER, (value('radius')[0], 0.0, value('length')[0])
        ok = size[0] > 0 and size[2] > 0
    elif shape.tag == 'sphere':
        kind, size = GeometryShape.SPHERE, (value('radius')[0], 0.0, 0.0)
        ok = size[0] > 0
    else:
        raise ModelError("link '%s': only box, cylinder and sphere collisions are supported" % link)
    if not ok:
        raise ModelError("link '%s': collision '%s' has a non-positive or non-finite size or pose"
                         % (link, name))
    return kind, size


def _urdf_origin(element):
    origin = element.find('origin') if element is not None else None
    if origin is None:
        return IDENTITY
    xyz = _floats(origin.get('xyz', '0 0 0'), 3, 'origin xyz')
    rpy = _floats(origin.get('rpy', '0 0 0'), 3, 'origin rpy')
    return tuple(xyz), quaternion_from_rpy(*rpy)


def _element_link(joint, tag):
    element = joint.find(tag)
    return element.get('link') if element is not None else None


def parse_urdf(xml):
    """The _ModelSpec of a URDF document; raises ModelError."""
    try:
        return _parse_urdf(xml)
    except _SyntaxError as error:
        raise ModelError('invalid URDF: %s' % error)


def _parse_urdf(xml):
    robot = _parse_xml(xml, 'robot')
    links = collections.OrderedDict()
    for link in robot.findall('link'):
        name = link.get('name')
        if not name:
            raise _SyntaxError('a <link> has no name')
        if name in links:
            raise _SyntaxError("duplicate link '%s'" % name)
        spec = _LinkSpec(name)
        inertial = link.find('inertial')
        if inertial is not None:
            spec.has_inertial = True
            spec.com = _urdf_origin(inertial)
            mass = inertial.find('mass')
            if mass is None:
                raise _SyntaxError("link '%s' <inertial> has no <mass>" % name)
            spec.mass = _attribute(mass, 'value', "link '%s' mass" % name)
            inertia = inertial.find('inertia')
            if inertia is None:
                raise _SyntaxError("link '%s' <inertial> has no <inertia>" % name)
            spec.inertia = tuple(_attribute(inertia, key, "link '%s' inertia" % name)
                                 for key in ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz'))
        for index, collision in enumerate(link.findall('collision')):
            collision_name = _collision_name(collision.get('name'), name, index)
            shape, size = _geometry(collision, name, collision_name)
            spec.collisions.append(_Collision(collision_name, shape, size,
                                              _urdf_origin(collision)))
        links[name] = spec
    if not links:
        raise _SyntaxError('no <link> in the robot')

    joints = collections.OrderedDict()
    children = collections.defaultdict(list)
    parent_of = {}
    for joint in robot.findall('joint'):
        name = joint.get('name')
        if not name:
            raise _SyntaxError('a <joint> has no name')
        if name in joints:
            raise ModelError("duplicate joint '%s'" % name)
        parent, child = _element_link(joint, 'parent'), _element_link(joint, 'child')
        for role, link in (('parent', parent), ('child', child)):
            if link not in links:
                raise ModelError("joint '%s' has unknown %s link '%s'" % (name, role, link))
        try:
            joint_type = JointType(joint.get('type'))
        except ValueError:
            raise ModelError("joint '%s': only revolute, continuous, prismatic and fixed joints "
                             "are supported" % name)
        if child in parent_of:
            raise ModelError("link '%s' is the child of more than one joint" % child)
        spec = _JointSpec(name, joint_type, parent, child)
        _urdf_origin(joint)
        axis = joint.find('axis')
        if joint_type != JointType.FIXED and axis is not None:
            if not any(_floats(axis.get('xyz', '1 0 0'), 3, "joint '%s' axis" % name)):
                raise ModelError("joint '%s' has a zero axis" % name)
        dynamics = joint.find('dynamics')
        if dynamics is not None:
            spec.damping = _attribute(dynamics, 'damping', "joint '%s' damping" % name, 0.0)
            friction = _attribute(dynamics, 'friction', "joint '%s' friction" % name, 0.0)
            # As urdfdom reads it: damping was declared if non-zero or if friction is zero.
            spec.has_damping = spec.damping != 0 or friction == 0
        limit = joint.find('limit')
        if limit is not None:
            effort = _attribute(limit, 'effort', "joint '%s' limit effort" % name, 0.0)
            # A missing effort reads as 0 and a joint that takes no effort is not what anyone
            # writes, so only a positive value limits.
            if effort > 0:
                spec.effort_limit = effort
        joints[name] = spec
        parent_of[child] = name
        children[parent].append(spec)

    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        raise _SyntaxError('the links form no single tree (roots: %s)'
                           % (', '.join(roots) or 'none, the joints form a loop'))
    ordered_links, ordered_joints = [], []

    def visit(name):
        ordered_links.append(links[name])
        for joint in children[name]:
            ordered_joints.append(joint)
            visit(joint.child)

    visit(roots[0])
    if len(ordered_links) != len(links):
        raise ModelError('the joints form a loop')
    world_rooted = roots[0] == 'world'
    if world_rooted:
        ordered_links.pop(0)
    if not ordered_links:
        raise ModelError("the URDF has no link besides 'world'")
    if any(link.name == 'world' for link in ordered_links):
        raise ModelError("a model link may not be called 'world'")
    spec = _ModelSpec(ordered_links, ordered_joints, world_rooted, is_static=False)
    _check_masses(spec)
    return spec


def _check_masses(spec):
    """What the ODE core refuses about masses, for the links that move."""
    joint_of = {joint.child: joint for joint in spec.joints}
    welded_to = {}  # link -> the moving link it rides on through fixed joints (None: the world)
    for link in spec.links:
        if link.mass < 0:
            raise ModelError("link '%s' has a negative mass" % link.name)
        joint = joint_of.get(link.name)
        if spec.is_static:
            welded_to[link.name] = None
        elif joint is None or joint.type != JointType.FIXED:
            welded_to[link.name] = link.name
        else:
            welded_to[link.name] = welded_to.get(joint.parent)  # `world`: None
    mass = collections.defaultdict(float)
    for link in spec.links:
        if welded_to[link.name] is not None and link.has_inertial:
            mass[welded_to[link.name]] += link.mass
    for link in spec.links:
        if welded_to[link.name] == link.name and not mass[link.name] > 0:
            raise ModelError("link '%s' moves but has no mass (give it an <inertial>)"
                             % link.name)


def _sdf_pose(element):
    pose = element.find('pose') if element is not None else None
    if pose is None:
        return IDENTITY
    if pose.get('relative_to'):
        raise ModelError('the bullet engine does not support <pose relative_to>')
    x, y, z, roll, pitch, yaw = _floats(pose.text, 6, 'pose')
    return (x, y, z), quaternion_from_rpy(roll, pitch, yaw)


def parse_sdf(xml):
    """The _ModelSpec of an SDF document with one model; raises ModelError.

    The bullet engine builds static models of any number of links and dynamic models of one link
    (a free body), with box, cylinder and sphere collisions; articulated models come as URDF.
    """
    try:
        return _parse_sdf(xml)
    except _SyntaxError as error:
        raise ModelError('invalid SDF: %s' % error)


def _parse_sdf(xml):
    sdf = _parse_xml(xml, 'sdf')
    models = sdf.findall('model')
    if not models:
        raise _SyntaxError('no <model> at the top level')
    model = models[0]
    for tag in ('include', 'joint', 'model'):
        if model.find(tag) is not None:
            raise ModelError('the bullet engine does not support <%s> in SDF models (give '
                             'articulated models as URDF)' % tag)
    is_static = (model.findtext('static') or 'false').strip() in ('true', '1')
    links = []
    for link in model.findall('link'):
        name = link.get('name')
        if not name:
            raise _SyntaxError('a <link> has no name')
        if any(other.name == name for other in links):
            raise ModelError("duplicate link '%s'" % name)
        # libsdformat's defaults for a link without <inertial>: 1 kg, unit inertia.
        spec = _LinkSpec(name, has_inertial=True, mass=1.0, inertia=(1.0, 0, 0, 1.0, 0, 1.0),
                         pose=_sdf_pose(link))
        inertial = link.find('inertial')
        if inertial is not None:
            spec.com = _sdf_pose(inertial)
            spec.mass = _floats(inertial.findtext('mass', '1'), 1, "link '%s' mass" % name)[0]
            inertia = inertial.find('inertia')
            defaults = dict(zip(('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz'), spec.inertia))
            spec.inertia = tuple(
                _floats(inertia.findtext(key, str(default)) if inertia is not None
                        else str(default), 1, "link '%s' %s" % (name, key))[0]
                for key, default in defaults.items())
        if (link.findtext('gravity') or 'true').strip() not in ('true', '1') and not is_static:
            raise ModelError('the bullet engine does not support <gravity>false</gravity>')
        for index, collision in enumerate(link.findall('collision')):
            collision_name = collision.get('name') or _collision_name('', name, index)
            shape, size = _geometry(collision, name, collision_name)
            spec.collisions.append(_Collision(collision_name, shape, size,
                                              _sdf_pose(collision)))
            mu = collision.findtext('surface/friction/ode/mu')
            if mu is not None:
                spec.friction = _floats(mu, 1, "collision '%s' mu" % collision_name)[0]
        links.append(spec)
    if not links:
        raise _SyntaxError('the model has no link')
    if not is_static:
        if len(links) > 1:
            raise ModelError('the bullet engine builds dynamic SDF models of one link only (give '
                             'articulated models as URDF)')
        if any(links[0].inertia[i] for i in (1, 2, 4)):
            raise ModelError("the bullet engine needs the inertia of SDF link '%s' in its "
                             "principal axes (ixy = ixz = iyz = 0)" % links[0].name)
    spec = _ModelSpec(links, [], world_rooted=False, is_static=is_static)
    _check_masses(spec)
    return spec


# ------------------------------------------------------------------------------------------------
# The world.

@dataclasses.dataclass
class _Joint:
    spec: _JointSpec
    index: int  # pybullet joint index (== index of its child link)


@dataclasses.dataclass
class _Model:
    name: str
    spec: _ModelSpec
    body: int  # pybullet body id
    link_index: dict  # link name -> pybullet link index (-1: the base)
    joints: dict  # joint name -> _Joint, in spec order
    base_inertial: tuple  # the base inertial frame in the base link frame (pybullet's base pose)
    spawn_base: tuple  # world transform of the base link frame at spawn
    anchored: set  # links welded to the world (all links of a static model)

    @property
    def canonical(self):
        return self.spec.links[0].name


@dataclasses.dataclass
class _Job:
    """An effort job on a joint, or a wrench job on a link, active on [start_ns, end_ns)."""
    model: str
    target: str  # bare joint name, or bare link name
    start_ns: int
    end_ns: int
    effort: float = 0.0
    reference_frame: str = ''  # wrench: force, torque and point are in this frame
    force: tuple = (0.0, 0.0, 0.0)
    torque: tuple = (0.0, 0.0, 0.0)
    point: tuple = (0.0, 0.0, 0.0)


def step_ns_of(step):
    return int(round(step * 1e9))


def _format_number(value):
    """As C++'s default ostream formatting (the ODE core's messages)."""
    return '%g' % value


def validate_params(params):
    """The ODE core's checks and messages (world.cpp validateParams)."""
    numbers = (params.step, *params.gravity, params.sor_pgs_w, params.sor_pgs_rms_error_tol,
               params.contact_surface_layer, params.contact_max_correcting_vel, params.cfm,
               params.erp)
    if not all(math.isfinite(n) for n in numbers):
        return Status.Error('SetPhysicsProperties: values must be finite')
    if params.step <= 0 or step_ns_of(params.step) < 1:
        return Status.Error('SetPhysicsProperties: time_step must be at least 1 ns')
    if not 0 <= params.erp <= 1:
        return Status.Error('SetPhysicsProperties: erp must be in [0, 1]')
    if (params.cfm < 0 or params.contact_surface_layer < 0 or params.contact_max_correcting_vel < 0
            or params.sor_pgs_rms_error_tol < 0 or params.sor_pgs_w <= 0):
        return Status.Error(
            'SetPhysicsProperties: cfm, contact_surface_layer, contact_max_correcting_vel and '
            'sor_pgs_rms_error_tol must be >= 0, sor_pgs_w > 0')
    if params.sor_pgs_iters < 1:
        return Status.Error('SetPhysicsProperties: sor_pgs_iters must be >= 1')
    if params.max_contacts > 0xffff:
        return Status.Error('SetPhysicsProperties: max_contacts must be <= 65535')
    if params.sor_pgs_precon_iters < 0 or params.max_contacts < 0:
        return Status.Error('SetPhysicsProperties: iteration and contact counts must be >= 0')
    return Status.Ok()


class BulletWorld:
    """A world of rigid-body models over pybullet, one physics client per world."""

    def __init__(self, params=None):
        params = params or PhysicsParams()
        status = validate_params(params)
        if not status.ok:
            raise ValueError(status.message)
        self._client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
        self._time_ns = 0
        self._step_count = 0
        self._models = collections.OrderedDict()
        self._joint_jobs = []
        self._wrench_jobs = []
        self._ground = self._client.createMultiBody(
            baseMass=0, baseCollisionShapeIndex=self._client.createCollisionShape(
                pybullet.GEOM_PLANE))
        self._client.changeDynamics(self._ground, -1, lateralFriction=GROUND_FRICTION)
        self._apply_params(params)

    def close(self):
        """Ends the physics client; the world is unusable afterwards."""
        if self._client is not None:
            self._client.disconnect()
            self._client = None

    # --- time and stepping --------------------------------------------------------------------

    def step(self):
        """Advances one step: applies the jobs covering the step's start time and the joint
        damping, integrates, resolves contacts, then advances time."""
        now = self._time_ns
        torques = collections.defaultdict(float)
        for job in self._joint_jobs:
            if job.start_ns <= now < job.end_ns:
                torques[(job.model, job.target)] += job.effort
        for model in self._models.values():
            for joint in model.joints.values():
                if joint.spec.damping and joint.spec.type != JointType.FIXED:
                    rate = self._client.getJointState(model.body, joint.index)[1]
                    torques[(model.name, joint.spec.name)] -= joint.spec.damping * rate
        for (model_name, joint_name), torque in torques.items():
            model = self._models[model_name]
            self._client.setJointMotorControl2(model.body, model.joints[joint_name].index,
                                               pybullet.TORQUE_CONTROL, force=torque)
        for job in self._wrench_jobs:
            if job.start_ns <= now < job.end_ns:
                self._apply_wrench(job)
        self._client.stepSimulation()
        self._time_ns += step_ns_of(self._params.step)
        self._step_count += 1
        self._joint_jobs = [j for j in self._joint_jobs if j.end_ns > self._time_ns]
        self._wrench_jobs = [j for j in self._wrench_jobs if j.end_ns > self._time_ns]

    def _apply_wrench(self, job):
        reference = self._entity_frame(job.reference_frame)
        if reference is None:  # the reference entity was deleted
            return
        frame = reference[0]
        model = self._models[job.model]
        self._client.applyExternalForce(
            model.body, model.link_index[job.target], rotate(frame[1], job.force),
            compose(frame, (job.point, IDENTITY[1]))[0], pybullet.WORLD_FRAME)
        self._client.applyExternalTorque(model.body, model.link_index[job.target],
                                         rotate(frame[1], job.torque), pybullet.WORLD_FRAME)

    def time_ns(self):
        return self._time_ns

    def time(self):
        """Sim time in seconds."""
        return self._time_ns * 1e-9

    def step_count(self):
        return self._step_count

    def params(self):
        return dataclasses.replace(self._params)

    @property
    def physics_client(self):
        """The pybullet client of this world, for measurements and tests that reach past the
        API (stepping bare pybullet, setting a joint rate)."""
        return self._client

    def set_params(self, params):
        """Refuses what the ODE core refuses (non-finite numbers, step < 1 ns, ...): world
        unchanged."""
        status = validate_params(params)
        if not status.ok:
            return status
        self._apply_params(params)
        return Status.Ok('SetPhysicsProperties: physics parameters set')

    def _apply_params(self, params):
        self._params = dataclasses.replace(params, gravity=Vec3(*params.gravity))
        self._client.setTimeStep(params.step)
        self._client.setGravity(*params.gravity)
        # The fields with a bullet counterpart. ODE's erp acts on joints and contacts alike;
        # sor_pgs_rms_error_tol becomes the residual at which bullet's solver may stop early
        # (0: every iteration, as ODE); contact_surface_layer is the penetration allowed without
        # correction in both. Kept and echoed only, without meaning here: quick_step (bullet has
        # one solver), sor_pgs_precon_iters and sor_pgs_w (pybullet exposes no SOR setting),
        # contact_max_correcting_vel, max_contacts (bullet keeps at most 4 points per pair).
        self._client.setPhysicsEngineParameter(
            numSolverIterations=params.sor_pgs_iters, erp=params.erp, contactERP=params.erp,
            frictionERP=params.erp, globalCFM=params.cfm,
            solverResidualThreshold=params.sor_pgs_rms_error_tol,
            contactSlop=params.contact_surface_layer)
        for model in self._models.values():
            self._set_sleeping(model.body)

    def _set_sleeping(self, body):
        """auto_disable_bodies is bullet's sleeping of bodies at rest."""
        state = (pybullet.ACTIVATION_STATE_ENABLE_SLEEPING if self._params.auto_disable_bodies
                 else pybullet.ACTIVATION_STATE_DISABLE_SLEEPING)
        self._client.changeDynamics(body, -1, activationState=state)

    # --- models -------------------------------------------------------------------------------

    def spawn(self, name, xml, model_format, pose, reference_frame=''):
        """Builds a model from URDF or SDF with its model frame at pose in reference_frame."""
        if not name:
            return Status.Error('SpawnModel: the model name is empty')
        if name in self._models:
            return Status.Error("SpawnModel: a model named '%s' already exists" % name)
        if not _pose_is_finite(pose):
            return Status.Error('SpawnModel: the initial pose is not finite or its quaternion '
                                'is zero')
        frame = self._entity_frame(reference_frame)
        if frame is None:
            return Status.Error("SpawnModel: reference frame '%s' not found" % reference_frame)
        try:
            spec = parse_urdf(xml) if model_format == ModelFormat.URDF else parse_sdf(xml)
        except ModelError as error:
            return Status.Error('SpawnModel: %s' % error)
        model_pose = compose(frame[0], _transform_from_pose(pose))
        try:
            model = (self._build_urdf(name, xml, spec, model_pose)
                     if model_format == ModelFormat.URDF else
                     self._build_sdf(name, spec, model_pose))
        except pybullet.error as error:
            return Status.Error('SpawnModel: bullet could not build the model: %s' % error)
        self._models[name] = model
        self._set_sleeping(model.body)
        return Status.Ok('SpawnModel: Successfully spawned entity')

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
            link_index[info[12].decode()] = index
            joints[info[1].decode()] = _Joint(joint_specs[info[1].decode()], index)
            self._client.setJointMotorControl2(body, index, pybullet.VELOCITY_CONTROL, force=0)
        for index in link_index.values():
            self._client.changeDynamics(body, index, linearDamping=0, angularDamping=0,
                                        lateralFriction=DEFAULT_FRICTION,
                                        maxJointVelocity=MAX_JOINT_VELOCITY)
        joint_of = {joint.child: joint for joint in spec.joints}
        anchored = set()
        if spec.world_rooted:
            for link in spec.links:  # parents first
                joint = joint_of[link.name]
                if joint.type == JointType.FIXED and (joint.parent == 'world'
                                                      or joint.parent in anchored):
                    anchored.add(link.name)
        return _Model(name, spec, body, link_index,
                      collections.OrderedDict((j.name, joints[j.name]) for j in spec.joints),
                      self._base_inertial(body), model_pose, anchored)

    def _base_inertial(self, body):
        info = self._client.getDynamicsInfo(body, -1)
        return tuple(info[3]), tuple(info[4])

    def _build_sdf(self, name, spec, model_pose):
        shapes = [self._compound_shape(link.collisions) for link in spec.links]
        base = spec.links[0]
        others = spec.links[1:]  # static models only: welded to the base
        base_pose = compose(model_pose, base.pose)
        in_base = [compose(invert(base.pose), link.pose) for link in others]
        body = self._client.createMultiBody(
            baseMass=0.0 if spec.is_static else base.mass, baseCollisionShapeIndex=shapes[0],
            basePosition=base_pose[0], baseOrientation=base_pose[1],
            baseInertialFramePosition=IDENTITY[0] if spec.is_static else base.com[0],
            baseInertialFrameOrientation=IDENTITY[1] if spec.is_static else base.com[1],
            linkMasses=[0.0] * len(others), linkCollisionShapeIndices=shapes[1:],
            linkVisualShapeIndices=[-1] * len(others),
            linkPositions=[t[0] for t in in_base], linkOrientations=[t[1] for t in in_base],
            linkInertialFramePositions=[IDENTITY[0]] * len(others),
            linkInertialFrameOrientations=[IDENTITY[1]] * len(others),
            linkParentIndices=[0] * len(others),
            linkJointTypes=[pybullet.JOINT_FIXED] * len(others),
            linkJointAxis=[(0, 0, 1)] * len(others))
        link_index = {link.name: index - 1 for index, link in enumerate(spec.links)}
        for link in spec.links:
            self._client.changeDynamics(body, link_index[link.name], linearDamping=0,
                                        angularDamping=0, lateralFriction=link.friction)
        if not spec.is_static:
            ixx, _, _, iyy, _, izz = base.inertia
            self._client.changeDynamics(body, -1, localInertiaDiagonal=(ixx, iyy, izz))
        anchored = {link.name for link in spec.links} if spec.is_static else set()
        return _Model(name, spec, body, link_index, collections.OrderedDict(),
                      self._base_inertial(body), base_pose, anchored)

    def _compound_shape(self, collisions):
        if not collisions:
            return -1
        kinds = {GeometryShape.BOX: pybullet.GEOM_BOX, GeometryShape.CYLINDER:
                 pybullet.GEOM_CYLINDER, GeometryShape.SPHERE: pybullet.GEOM_SPHERE}
        return self._client.createCollisionShapeArray(
            shapeTypes=[kinds[c.shape] for c in collisions],
            halfExtents=[[s / 2 for s in c.size] if c.shape == GeometryShape.BOX else [0, 0, 0]
                         for c in collisions],
            radii=[c.size[0] for c in collisions], lengths=[c.size[2] for c in collisions],
            collisionFramePositions=[c.origin[0] for c in collisions],
            collisionFrameOrientations=[c.origin[1] for c in collisions])

    def delete_model(self, name):
        model = self._models.get(name)
        if model is None:
            return Status.Error('DeleteModel: model does not exist')
        self._client.removeBody(model.body)
        del self._models[name]
        self._joint_jobs = [j for j in self._joint_jobs if j.model != name]
        self._wrench_jobs = [j for j in self._wrench_jobs if j.model != name]
        return Status.Ok('DeleteModel: successfully deleted model')

    def model_names(self):
        return list(self._models)

    def has_model(self, name):
        return name in self._models

    def model_properties(self, name):
        """(Status, ModelInfo or None)."""
        model = self._models.get(name)
        if model is None:
            return Status.Error('GetModelProperties: model does not exist'), None
        links = model.spec.links
        return Status.Ok('GetModelProperties: got properties'), ModelInfo(
            name=name, canonical_link='%s::%s' % (name, model.canonical),
            links=['%s::%s' % (name, link.name) for link in links],
            geoms=[c.name for link in links for c in link.collisions],
            joints=list(model.joints), is_static=model.spec.is_static)

    def model_state(self, name, reference_frame=''):
        """(Status, Pose, Twist) of the model's canonical (root) link frame in reference_frame."""
        model = self._models.get(name)
        if model is None:
            return Status.Error('GetModelState: model does not exist'), None, None
        reference = self._entity_frame(reference_frame)
        if reference is None:
            return (Status.Error("GetModelState: reference frame '%s' not found"
                                 % reference_frame), None, None)
        pose, twist = _relative(self._link_state(model, model.canonical), reference)
        return Status.Ok('GetModelState: got properties'), pose, twist

    def set_model_state(self, name, pose, twist, reference_frame=''):
        """Moves the whole model rigidly, its joints kept, so that its canonical link frame gets
        pose and twist in reference_frame; the joint rates become zero."""
        model = self._models.get(name)
        if model is None:
            return Status.Error('SetModelState: model does not exist')
        if not _pose_is_finite(pose) or not _twist_is_finite(twist):
            return Status.Error('SetModelState: the pose or twist is not finite, or the '
                                'quaternion is zero')
        reference = self._entity_frame(reference_frame)
        if reference is None:
            return Status.Error("SetModelState: reference frame '%s' not found" % reference_frame)
        self._move_model(model, model.canonical, reference[0], pose, twist)
        return Status.Ok('SetModelState: set model state done')

    def set_model_configuration(self, name, joints, positions):
        """Sets joint positions with zero velocity, moving the links below each joint."""
        model = self._models.get(name)
        if model is None:
            return Status.Error('SetModelConfiguration: model does not exist')
        if len(joints) != len(positions):
            return Status.Error('SetModelConfiguration: joint_names and joint_positions differ '
                                'in length')
        for joint, position in zip(joints, positions):
            if joint not in model.joints:
                return Status.Error("SetModelConfiguration: joint '%s' not found in model"
                                    % joint)
            if not math.isfinite(position):
                return Status.Error("SetModelConfiguration: position of '%s' is not finite"
                                    % joint)
        wanted = dict(zip(joints, positions))
        for joint in model.joints.values():
            if joint.spec.type != JointType.FIXED:
                position = wanted.get(joint.spec.name,
                                      self._client.getJointState(model.body, joint.index)[0])
                self._client.resetJointState(model.body, joint.index, position, 0.0)
        self._client.resetBaseVelocity(model.body, (0, 0, 0), (0, 0, 0))
        return Status.Ok('SetModelConfiguration: success')

    # --- links --------------------------------------------------------------------------------

    def _find_link(self, scoped_link):
        """(model, bare link name) of "model::link", or (None, None)."""
        for model in self._models.values():
            prefix = model.name + '::'
            if scoped_link.startswith(prefix) and scoped_link[len(prefix):] in model.link_index:
                bare = scoped_link[len(prefix):]
                if not (model.spec.world_rooted and bare == 'world'):
                    return model, bare
        return None, None

    def link_properties(self, scoped_link):
        """(Status, LinkInfo or None)."""
        model, link_name = self._find_link(scoped_link)
        if model is None:
            return Status.Error('GetLinkProperties: link not found'), None
        spec = next(link for link in model.spec.links if link.name == link_name)
        return Status.Ok('GetLinkProperties: got properties'), LinkInfo(
            model.name, link_name, _pose_from_transform(spec.com), spec.mass, *spec.inertia,
            gravity_mode=True)

    def link_state(self, scoped_link, reference_frame=''):
        """(Status, Pose, Twist) of the link frame in reference_frame."""
        model, link_name = self._find_link(scoped_link)
        if model is None:
            return (Status.Error('GetLinkState: link not found, did you forget to scope the link '
                                 'by model name?'), None, None)
        reference = self._entity_frame(reference_frame)
        if reference is None:
            return (Status.Error("GetLinkState: reference frame '%s' not found"
                                 % reference_frame), None, None)
        pose, twist = _relative(self._link_state(model, link_name), reference)
        return Status.Ok('GetLinkState: got state'), pose, twist

    def set_link_state(self, scoped_link, pose, twist, reference_frame=''):
        """Sets the state of a model's free root link (with the links welded to it), which moves
        the model. A bullet articulation keeps its other links on their joints, so those are
        refused (the ODE engine sets them and lets the joints pull them back)."""
        model, link_name = self._find_link(scoped_link)
        if model is None:
            return Status.Error('SetLinkState: link not found')
        if link_name in model.anchored:
            return Status.Error("SetLinkState: link '%s' is anchored to the world; move its model "
                                "with set_model_state" % scoped_link)
        if not self._welded_to_base(model, link_name):
            return Status.Error("SetLinkState: link '%s' hangs on a joint, and the bullet engine "
                                "sets only a model's free root link; use set_model_configuration"
                                % scoped_link)
        if not _pose_is_finite(pose) or not _twist_is_finite(twist):
            return Status.Error('SetLinkState: the pose or twist is not finite, or the quaternion '
                                'is zero')
        reference = self._entity_frame(reference_frame)
        if reference is None:
            return Status.Error("SetLinkState: reference frame '%s' not found" % reference_frame)
        self._move_model(model, link_name, reference[0], pose, twist)
        return Status.Ok('SetLinkState: success')

    def link_names(self):
        return ['%s::%s' % (model.name, link.name) for model in self._models.values()
                for link in model.spec.links]

    # --- joints -------------------------------------------------------------------------------

    def _find_joint(self, joint):
        """Scoped "model::joint" first, then the bare name in spawn order (as the ODE core)."""
        for model in self._models.values():
            prefix = model.name + '::'
            if joint.startswith(prefix) and joint[len(prefix):] in model.joints:
                return model, model.joints[joint[len(prefix):]]
        for model in self._models.values():
            if joint in model.joints:
                return model, model.joints[joint]
        return None, None

    def joint_info(self, joint):
        """(Status, JointInfo or None)."""
        model, found = self._find_joint(joint)
        if model is None:
            return Status.Error('GetJointProperties: joint not found'), None
        position, rate = 0.0, 0.0
        if found.spec.type != JointType.FIXED:
            position, rate = self._client.getJointState(model.body, found.index)[:2]
        return Status.Ok('GetJointProperties: got properties'), JointInfo(
            model.name, found.spec.name, found.spec.type, found.spec.has_damping,
            found.spec.damping, position, rate)

    def apply_joint_effort(self, joint, effort, start_ns, duration_ns):
        """Queues an effort job on the window rules of world.h."""
        model, found = self._find_joint(joint)
        if model is None:
            return Status.Error('ApplyJointEffort: joint not found')
        if found.spec.type == JointType.FIXED:
            return Status.Error("ApplyJointEffort: joint '%s' is fixed and takes no effort"
                                % joint)
        if not math.isfinite(effort):
            return Status.Error('ApplyJointEffort: effort is not finite')
        window, note = self._job_window(start_ns, duration_ns)
        if window is not None:
            limit = found.spec.effort_limit
            if abs(effort) > limit:
                effort = math.copysign(limit, effort)
                note += "; clamped to the joint's effort limit " + _format_number(limit)
            self._joint_jobs.append(_Job(model.name, found.spec.name, *window, effort=effort))
        return Status.Ok('ApplyJointEffort: effort set' + note)

    def clear_joint_forces(self, joint):
        """Drops every pending job on joints of that name, bare (any model) or scoped."""
        self._joint_jobs = [j for j in self._joint_jobs
                            if joint not in (j.target, '%s::%s' % (j.model, j.target))]

    def apply_body_wrench(self, scoped_link, reference_frame, reference_point, force, torque,
                          start_ns, duration_ns):
        """Wrench on a link: force and torque in reference_frame's orientation, the force applied
        at reference_point (in reference_frame), the frame followed at every step."""
        model, link_name = self._find_link(scoped_link)
        if model is None:
            return Status.Error('ApplyBodyWrench: body does not exist')
        if link_name in model.anchored:
            return Status.Error("ApplyBodyWrench: body '%s' is anchored to the world"
                                % scoped_link)
        if self._entity_frame(reference_frame) is None:
            return Status.Error("ApplyBodyWrench: reference frame '%s' not found"
                                % reference_frame)
        if not all(math.isfinite(v) for v in (*reference_point, *force, *torque)):
            return Status.Error('ApplyBodyWrench: wrench or reference point is not finite')
        window, note = self._job_window(start_ns, duration_ns)
        if window is not None:
            self._wrench_jobs.append(_Job(model.name, link_name, *window,
                                          reference_frame=reference_frame, force=tuple(force),
                                          torque=tuple(torque), point=tuple(reference_point)))
        return Status.Ok('ApplyBodyWrench: wrench set' + note)

    def clear_body_wrenches(self, scoped_link):
        self._wrench_jobs = [j for j in self._wrench_jobs
                             if '%s::%s' % (j.model, j.target) != scoped_link]

    def _job_window(self, start_ns, duration_ns):
        """((start_ns, end_ns) or None for nothing to do, note for the status message)."""
        if duration_ns == 0:
            return None, '; duration is 0, so nothing was applied'
        start_ns = max(int(start_ns), self._time_ns)
        step_ns = step_ns_of(self._params.step)
        if duration_ns < 0:
            return (start_ns, math.inf), ''
        if duration_ns < step_ns:
            # [start, start + step) holds exactly one step start, wherever start falls.
            return ((start_ns, start_ns + step_ns),
                    '; duration is shorter than the step, so it acts for exactly one step')
        return (start_ns, start_ns + int(duration_ns)), ''

    # --- reset --------------------------------------------------------------------------------

    def reset_world(self):
        """Every model back to its spawn pose and configuration, zero velocity; drops jobs."""
        for model in self._models.values():
            inertial = compose(model.spawn_base, model.base_inertial)
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
        self._step_count = 0

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
                        _pose_from_transform(compose(frame, collision.origin))))
        return shapes

    # --- frames -------------------------------------------------------------------------------

    def _link_frame(self, model, index):
        """World transform of a link frame (pybullet index, -1: base). pybullet keeps the base
        at its inertial frame, and reports a link's frame apart from its centre of mass."""
        if index == -1:
            inertial = self._client.getBasePositionAndOrientation(model.body)
            return compose(inertial, invert(model.base_inertial))
        state = self._client.getLinkState(model.body, index, computeForwardKinematics=True)
        return tuple(state[4]), tuple(state[5])

    def _link_state(self, model, link_name):
        """(world transform, linear, angular) of a link frame; the linear velocity is that of
        the frame's origin, as the ODE core and Gazebo report it."""
        index = model.link_index[link_name]
        if index == -1:
            com = self._client.getBasePositionAndOrientation(model.body)[0]
            linear, angular = self._client.getBaseVelocity(model.body)
        else:
            state = self._client.getLinkState(model.body, index, computeLinkVelocity=True,
                                              computeForwardKinematics=True)
            com, linear, angular = state[0], state[6], state[7]
        frame = self._link_frame(model, index)
        return frame, add(linear, cross(angular, sub(frame[0], com))), tuple(angular)

    def _entity_frame(self, entity):
        """(transform, linear, angular) of "" / "world", a model (its canonical link) or
        "model::link"; None if there is no such entity."""
        if entity in WORLD_FRAMES:
            return IDENTITY, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        if entity in self._models:
            model = self._models[entity]
            return self._link_state(model, model.canonical)
        model, link_name = self._find_link(entity)
        if model is None:
            return None
        return self._link_state(model, link_name)

    def _welded_to_base(self, model, link_name):
        """Whether only fixed joints lie between the link and the pybullet base."""
        parent_joint = {joint.spec.child: joint for joint in model.joints.values()}
        while link_name in parent_joint:
            if parent_joint[link_name].spec.type != JointType.FIXED:
                return False
            link_name = parent_joint[link_name].spec.parent
        return True

    def _move_model(self, model, link_name, reference, pose, twist):
        """Moves the model rigidly, joint positions kept and joint rates zeroed, so that the
        frame of link_name gets pose and twist (in the reference transform's axes)."""
        target = compose(reference, _transform_from_pose(pose))
        motion = compose(target, invert(self._link_frame(model, model.link_index[link_name])))
        inertial = compose(compose(motion, self._link_frame(model, -1)), model.base_inertial)
        self._client.resetBasePositionAndOrientation(model.body, *inertial)
        for joint in model.joints.values():
            if joint.spec.type != JointType.FIXED:
                position = self._client.getJointState(model.body, joint.index)[0]
                self._client.resetJointState(model.body, joint.index, position, 0.0)
        linear = rotate(reference[1], tuple(twist.linear))
        angular = rotate(reference[1], tuple(twist.angular))
        # pybullet's base velocity is that of its centre of mass. A base fixed to the world
        # does not move: the twist is ignored there.
        com_linear = add(linear, cross(angular, sub(inertial[0], target[0])))
        self._client.resetBaseVelocity(model.body, com_linear, angular)


def _relative(state, reference):
    """Gazebo's convention for a state relative to an entity: pose in the entity frame,
    velocities relative to the entity's and expressed in its axes."""
    (frame, linear, angular), (ref, ref_linear, ref_angular) = state, reference
    inverse = invert(ref)
    pose = compose(inverse, frame)
    linear = rotate(inverse[1], sub(linear, ref_linear))
    angular = rotate(inverse[1], sub(angular, ref_angular))
    return _pose_from_transform(pose), Twist(Vec3(*linear), Vec3(*angular))
