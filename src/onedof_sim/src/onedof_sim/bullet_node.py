"""The simulator node on pybullet: Gazebo's ROS API (gazebo_ros services and topics) over a
BulletWorld, with the same names, parameters and status texts as the ODE node (src/ros/).

The step loop runs in the main thread; rospy runs each service callback in a thread of its own.
They share one lock around the world, held only for world calls, never during ROS I/O.
"""
import math
import signal
import sys
import threading
import time
import xml.etree.ElementTree as ElementTree

import rospy
from geometry_msgs.msg import Pose as PoseMsg
from geometry_msgs.msg import Twist as TwistMsg
from geometry_msgs.msg import Vector3
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty, EmptyResponse
from visualization_msgs.msg import Marker, MarkerArray

from onedof_sim.bullet_world import (BulletWorld, GeometryShape, JointType, ModelFormat,
                                     PhysicsParams, Pose, Quat, Status, Twist, Vec3)
from onedof_sim.msg import LinkState, LinkStates, ModelState, ModelStates
from onedof_sim.srv import (ApplyBodyWrench, ApplyBodyWrenchResponse, ApplyJointEffort,
                            ApplyJointEffortResponse, DeleteModel, DeleteModelResponse,
                            GetJointProperties, GetJointPropertiesResponse, GetLinkProperties,
                            GetLinkPropertiesResponse, GetLinkState, GetLinkStateResponse,
                            GetModelProperties, GetModelPropertiesResponse, GetModelState,
                            GetModelStateResponse, GetPhysicsProperties,
                            GetPhysicsPropertiesResponse, GetWorldProperties,
                            GetWorldPropertiesResponse, JointRequest, JointRequestResponse,
                            BodyRequest, BodyRequestResponse, SetLinkState, SetLinkStateResponse,
                            SetModelConfiguration, SetModelConfigurationResponse, SetModelState,
                            SetModelStateResponse, SetPhysicsProperties,
                            SetPhysicsPropertiesResponse, SpawnModel, SpawnModelResponse)

ENGINE = 'bullet'
# If the paced loop falls further behind than this, it drops the backlog instead of racing.
MAX_PACING_LAG = 0.1  # s
COLLISION_MARKERS_FREQUENCY = 10.0  # Hz of sim time
GROUND_MARKER_SIZE = 10.0  # m, the plane drawn as a thin square
PARAM_REFRESH_PERIOD = 0.1  # s of wall time between reads of ~pub_clock_frequency
PAUSED_WAIT = 0.05  # s; lets the loop notice a shutdown while paused
GIL_SWITCH_INTERVAL = 0.0002  # s, see main()


# --- conversions between ROS messages and the core's types ---------------------------------------

def to_ns(stamp):
    """ROS time or duration to integer nanoseconds (negative durations included)."""
    return int(stamp.secs) * 1000000000 + int(stamp.nsecs)


def from_ns(ns):
    return rospy.Time(ns // 1000000000, ns % 1000000000)


def _finite(*vectors):
    return all(math.isfinite(getattr(v, axis)) for v in vectors for axis in 'xyz')


def pose_is_finite(pose):
    return _finite(pose.position) and all(
        math.isfinite(getattr(pose.orientation, axis)) for axis in 'wxyz')


def twist_is_finite(twist):
    return _finite(twist.linear, twist.angular)


def to_core_pose(msg):
    """Normalises the quaternion as Gazebo does; an all-zero one (an unset field) is identity."""
    q = msg.orientation
    norm = math.sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z)
    orientation = Quat(q.w / norm, q.x / norm, q.y / norm, q.z / norm) if norm > 1e-12 else Quat()
    return Pose(Vec3(msg.position.x, msg.position.y, msg.position.z), orientation)


def to_core_twist(msg):
    return Twist(Vec3(msg.linear.x, msg.linear.y, msg.linear.z),
                 Vec3(msg.angular.x, msg.angular.y, msg.angular.z))


def to_pose_msg(pose):
    msg = PoseMsg()
    msg.position.x, msg.position.y, msg.position.z = pose.position
    o = pose.orientation
    msg.orientation.w, msg.orientation.x, msg.orientation.y, msg.orientation.z = o
    return msg


def to_twist_msg(twist):
    msg = TwistMsg()
    msg.linear = Vector3(*twist.linear)
    msg.angular = Vector3(*twist.angular)
    return msg


def bare_name(scoped):
    return scoped.rpartition('::')[2]


def prefixed(service, message):
    """Gazebo's status messages start with the service name."""
    prefix = service + ': '
    return message if message.startswith(prefix) else prefix + message


def is_due(now_ns, last_ns, frequency):
    """Whether a throttled output is due at sim time now_ns (frequency <= 0: every step). Time
    going back (reset_simulation) makes it due at once."""
    if frequency <= 0 or last_ns < 0 or now_ns < last_ns:
        return True
    return now_ns - last_ns >= 1e9 / frequency


def detect_model_format(xml):
    """(Status, ModelFormat): which format model_xml is, from its root element. Gazebo accepts
    either on both spawn services."""
    try:
        root = ElementTree.fromstring(xml)
    except ElementTree.ParseError as error:
        return Status.Error('model_xml is not well-formed XML: %s' % error), None
    if root.tag == 'robot':
        return Status.Ok(), ModelFormat.URDF
    if root.tag == 'sdf':
        return Status.Ok(), ModelFormat.SDF
    return (Status.Error('model_xml has root element <%s>, expected <robot> (URDF) or <sdf> (SDF)'
                         % root.tag), None)


JOINT_TYPE_CONSTANTS = {
    JointType.REVOLUTE: GetJointPropertiesResponse.REVOLUTE,
    JointType.CONTINUOUS: GetJointPropertiesResponse.REVOLUTE,
    JointType.PRISMATIC: GetJointPropertiesResponse.PRISMATIC,
    JointType.FIXED: GetJointPropertiesResponse.FIXED,
}


def to_marker(shape, marker_id):
    marker = Marker()
    marker.header.frame_id = 'world'
    marker.ns = '%s::%s' % (shape.model, shape.link)
    marker.id = marker_id
    marker.action = Marker.ADD
    marker.pose = to_pose_msg(shape.pose)
    marker.color.r = marker.color.g = marker.color.b = 0.6
    marker.color.a = 0.8
    if shape.shape == GeometryShape.BOX:
        marker.type = Marker.CUBE
        marker.scale = Vector3(*shape.size)
    elif shape.shape == GeometryShape.CYLINDER:
        marker.type = Marker.CYLINDER
        marker.scale = Vector3(2 * shape.size.x, 2 * shape.size.x, shape.size.z)
    elif shape.shape == GeometryShape.SPHERE:
        marker.type = Marker.SPHERE
        marker.scale = Vector3(*[2 * shape.size.x] * 3)
    else:
        marker.type = Marker.CUBE
        marker.scale = Vector3(GROUND_MARKER_SIZE, GROUND_MARKER_SIZE, 0.001)
        marker.color.a = 0.3
    return marker


# --- start-up parameters -------------------------------------------------------------------------

class OptionError(Exception):
    pass


class NodeOptions:
    """Start-up settings, as the ODE node's (private parameters and gzserver's flags)."""

    def __init__(self):
        self.physics = PhysicsParams()
        self.max_update_rate = 1000.0  # steps per wall second; 0 = as fast as possible
        self.paused = False
        self.states_publish_frequency = 0.0  # Hz of sim time; 0 = every step


def _read_param(name, kinds, current):
    """~name when set; a value of the wrong type is an error, not a silent default."""
    if not rospy.has_param('~' + name):
        return current
    value = rospy.get_param('~' + name)
    if isinstance(value, bool) != (kinds == (bool,)) or not isinstance(value, kinds):
        raise OptionError('parameter %s has the wrong type' % rospy.resolve_name('~' + name))
    return value


def _read_count(name, current):
    value = _read_param(name, (int,), current)
    if value < 0:
        raise OptionError('parameter %s must be >= 0' % rospy.resolve_name('~' + name))
    return value


def _read_rate(name, current):
    value = float(_read_param(name, (int, float), current))
    if not math.isfinite(value) or value < 0:
        raise OptionError('parameter %s must be finite and >= 0' % rospy.resolve_name('~' + name))
    return value


def _read_gravity():
    """~gravity as a list [x, y, z] or a string of three numbers ("0 0 -9.8", "[0, 0, -9.8]");
    None when unset."""
    if not rospy.has_param('~gravity'):
        return None
    value = rospy.get_param('~gravity')
    if isinstance(value, str):
        try:
            value = [float(v) for v in value.replace('[', ' ').replace(']', ' ')
                     .replace(',', ' ').split()]
        except ValueError:
            value = []
    if (not isinstance(value, list) or len(value) != 3
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise OptionError('parameter %s must be three numbers [x, y, z]'
                          % rospy.resolve_name('~gravity'))
    return Vec3(*map(float, value))


def read_node_options(args):
    """Private parameters (the ODE node's names, see src/ros/gazebo_api.cpp) and gzserver's
    flags in args (without the program name and ROS remappings); raises OptionError."""
    options = NodeOptions()
    p = options.physics
    reals = (int, float)
    p.step = float(_read_param('time_step', reals, p.step))
    options.max_update_rate = _read_rate('max_update_rate', options.max_update_rate)
    options.paused = _read_param('paused', (bool,), options.paused)
    p.quick_step = _read_param('quick_step', (bool,), p.quick_step)
    p.auto_disable_bodies = _read_param('auto_disable_bodies', (bool,), p.auto_disable_bodies)
    p.sor_pgs_precon_iters = _read_count('sor_pgs_precon_iters', p.sor_pgs_precon_iters)
    p.sor_pgs_iters = _read_count('sor_pgs_iters', p.sor_pgs_iters)
    for name in ('sor_pgs_w', 'sor_pgs_rms_error_tol', 'contact_surface_layer',
                 'contact_max_correcting_vel', 'cfm', 'erp'):
        setattr(p, name, float(_read_param(name, reals, getattr(p, name))))
    p.max_contacts = _read_count('max_contacts', p.max_contacts)
    options.states_publish_frequency = _read_rate('states_publish_frequency',
                                                  options.states_publish_frequency)
    gravity = _read_gravity()
    if gravity is not None:
        p.gravity = gravity
    index = 0
    while index < len(args):
        if args[index] in ('-u', '--pause'):
            options.paused = True
        elif args[index] == '-e' and index + 1 < len(args):
            index += 1
            if args[index] != ENGINE:
                raise OptionError("physics engine '%s' is not supported by this node (it is %s)"
                                  % (args[index], ENGINE))
        else:
            rospy.logwarn("ignoring command-line argument '%s'", args[index])
        index += 1
    return options


# --- the node ------------------------------------------------------------------------------------

class WorldLock:
    """The lock around the world. Counts waiting service callbacks so that the step loop, which
    re-locks right after unlocking when running as fast as possible, lets them in first."""

    def __init__(self):
        self._lock = threading.Lock()
        self.waiting = 0  # read by the loop without the lock: a hint, not a guarantee
        self._count_lock = threading.Lock()

    def __enter__(self):
        with self._count_lock:
            self.waiting += 1
        self._lock.acquire()
        with self._count_lock:
            self.waiting -= 1
        return self

    def __exit__(self, *exc):
        self._lock.release()

    @property
    def raw(self):
        return self._lock


def refuse(response, message):
    """Bad input: the call succeeds with success False and the reason, and the node says it."""
    response.success = False
    response.status_message = message
    rospy.logwarn(message)
    return response


def succeed(response, message):
    response.success = True
    response.status_message = message
    return response


class BulletGazeboApi:
    """Gazebo's ROS API over a BulletWorld; run() steps it until ROS shuts down."""

    def __init__(self, options):
        self._world = BulletWorld(options.physics)  # ValueError on invalid parameters
        self._lock = WorldLock()
        self._unpaused = threading.Condition(self._lock.raw)
        self._paused = options.paused
        self._max_update_rate = options.max_update_rate
        self._states_publish_frequency = options.states_publish_frequency
        self._clock_frequency = 0.0
        self._next_param_refresh = 0.0
        self._deadline = 0.0
        self._last_clock_ns = -1
        self._last_states_ns = -1
        self._last_markers_ns = -1

        if not rospy.has_param('/use_sim_time'):
            rospy.set_param('/use_sim_time', True)
        self._clock_pub = rospy.Publisher('/clock', Clock, queue_size=10)
        self._model_states_pub = rospy.Publisher('~model_states', ModelStates, queue_size=1)
        self._link_states_pub = rospy.Publisher('~link_states', LinkStates, queue_size=1)
        self._markers_pub = rospy.Publisher('~collision_markers', MarkerArray, queue_size=1)
        services = [
            ('get_joint_properties', GetJointProperties, self.get_joint_properties),
            ('apply_joint_effort', ApplyJointEffort, self.apply_joint_effort),
            ('clear_joint_forces', JointRequest, self.clear_joint_forces),
            ('apply_body_wrench', ApplyBodyWrench, self.apply_body_wrench),
            ('clear_body_wrenches', BodyRequest, self.clear_body_wrenches),
            ('spawn_urdf_model', SpawnModel, self.spawn_urdf_model),
            ('spawn_sdf_model', SpawnModel, self.spawn_sdf_model),
            ('delete_model', DeleteModel, self.delete_model),
            ('get_model_state', GetModelState, self.get_model_state),
            ('set_model_state', SetModelState, self.set_model_state),
            ('get_link_state', GetLinkState, self.get_link_state),
            ('set_link_state', SetLinkState, self.set_link_state),
            ('set_model_configuration', SetModelConfiguration, self.set_model_configuration),
            ('get_model_properties', GetModelProperties, self.get_model_properties),
            ('get_world_properties', GetWorldProperties, self.get_world_properties),
            ('get_link_properties', GetLinkProperties, self.get_link_properties),
            ('get_physics_properties', GetPhysicsProperties, self.get_physics_properties),
            ('set_physics_properties', SetPhysicsProperties, self.set_physics_properties),
            ('pause_physics', Empty, self.pause_physics),
            ('reset_simulation', Empty, self.reset_simulation),
            ('reset_world', Empty, self.reset_world),
            # Last on purpose: clients (and our tests) take it as the sign that all are up.
            ('unpause_physics', Empty, self.unpause_physics),
        ]
        self._services = [rospy.Service('~' + name, kind, handler)
                          for name, kind, handler in services]
        self._subscribers = [
            rospy.Subscriber('~set_model_state', ModelState, self._set_model_state_topic,
                             queue_size=10),
            rospy.Subscriber('~set_link_state', LinkState, self._set_link_state_topic,
                             queue_size=10),
        ]
        rospy.loginfo('onedof_sim (bullet): serving the Gazebo API under %s (step %g s, '
                      'max_update_rate %g Hz%s)', rospy.get_name(), options.physics.step,
                      self._max_update_rate, ', paused' if self._paused else '')

    def close(self):
        self._world.close()

    # --- the step loop ----------------------------------------------------------------------

    def run(self, stop):
        """Steps until `stop` (a threading.Event) is set or ROS shuts down."""
        was_stepping, paced_rate = False, None
        while not stop.is_set() and not rospy.is_shutdown():
            out = self._step_once()
            if out is None:
                was_stepping = False
                continue
            resumed = not was_stepping or out['max_update_rate'] != paced_rate
            was_stepping, paced_rate = True, out['max_update_rate']
            self._publish(out)
            self._pace(out['max_update_rate'], resumed)

    def _step_once(self):
        """Steps once under the lock; returns what to publish, or None when paused."""
        want_model_states = self._model_states_pub.get_num_connections() > 0
        want_link_states = self._link_states_pub.get_num_connections() > 0
        want_markers = self._markers_pub.get_num_connections() > 0
        while self._lock.waiting > 0:
            time.sleep(0)  # let waiting service callbacks in first
        with self._lock.raw:
            if self._paused:
                self._unpaused.wait(PAUSED_WAIT)
                return None
            world = self._world
            world.step()
            now_ns = world.time_ns()
            out = {'time_ns': now_ns, 'max_update_rate': self._max_update_rate}
            states_due = is_due(now_ns, self._last_states_ns, self._states_publish_frequency)
            if states_due and (want_model_states or want_link_states):
                self._last_states_ns = now_ns
            if states_due and want_model_states:
                states = ModelStates()
                for name in world.model_names():
                    _, pose, twist = world.model_state(name)
                    states.name.append(name)
                    states.pose.append(to_pose_msg(pose))
                    states.twist.append(to_twist_msg(twist))
                out['model_states'] = states
            if states_due and want_link_states:
                states = LinkStates()
                for name in world.link_names():
                    _, pose, twist = world.link_state(name)
                    states.name.append(name)
                    states.pose.append(to_pose_msg(pose))
                    states.twist.append(to_twist_msg(twist))
                out['link_states'] = states
            if want_markers and is_due(now_ns, self._last_markers_ns,
                                       COLLISION_MARKERS_FREQUENCY):
                self._last_markers_ns = now_ns
                out['shapes'] = world.collision_shapes()
        return out

    def _publish(self, out):
        self._refresh_clock_frequency()
        if is_due(out['time_ns'], self._last_clock_ns, self._clock_frequency):
            self._last_clock_ns = out['time_ns']
            self._clock_pub.publish(Clock(from_ns(out['time_ns'])))
        if 'model_states' in out:
            self._model_states_pub.publish(out['model_states'])
        if 'link_states' in out:
            self._link_states_pub.publish(out['link_states'])
        if 'shapes' in out:
            clear = Marker(action=Marker.DELETEALL)  # first, so shapes of deleted models go
            clear.header.frame_id = 'world'
            self._markers_pub.publish(MarkerArray(
                [clear] + [to_marker(shape, i) for i, shape in enumerate(out['shapes'])]))

    def _refresh_clock_frequency(self):
        """~pub_clock_frequency may change while running; re-read ten times per wall second."""
        now = time.monotonic()
        if now < self._next_param_refresh:
            return
        self._next_param_refresh = now + PARAM_REFRESH_PERIOD
        frequency = rospy.get_param('~pub_clock_frequency', 0.0)
        valid = isinstance(frequency, (int, float)) and not isinstance(frequency, bool)
        self._clock_frequency = float(frequency) if valid and math.isfinite(frequency) else 0.0

    def _pace(self, max_update_rate, resumed):
        """Sleeps until this step's absolute deadline (origin + n periods: no drift)."""
        now = time.monotonic()
        if max_update_rate <= 0:
            return
        if resumed:
            self._deadline = now
        self._deadline += 1.0 / max_update_rate
        if self._deadline > now:
            time.sleep(self._deadline - now)
        elif now - self._deadline > MAX_PACING_LAG:
            self._deadline = now  # far behind (a loaded machine): run on from now

    # --- joints -----------------------------------------------------------------------------

    def get_joint_properties(self, req):
        res = GetJointPropertiesResponse()
        with self._lock:
            found, joint = self._world.joint_info(req.joint_name)
        if not found.ok:
            return refuse(res, 'GetJointProperties: joint not found')
        res.type = JOINT_TYPE_CONSTANTS[joint.type]
        if joint.has_damping:
            res.damping.append(joint.damping)
        res.position.append(joint.position)
        res.rate.append(joint.rate)
        return succeed(res, 'GetJointProperties: got properties')

    def apply_joint_effort(self, req):
        res = ApplyJointEffortResponse()
        with self._lock:
            found, _ = self._world.joint_info(req.joint_name)
            if found.ok:
                applied = self._world.apply_joint_effort(
                    req.joint_name, req.effort, to_ns(req.start_time), to_ns(req.duration))
        if not found.ok:
            return refuse(res, 'ApplyJointEffort: joint not found')
        if not applied.ok:
            return refuse(res, prefixed('ApplyJointEffort', applied.message))
        return succeed(res, prefixed('ApplyJointEffort', applied.message))

    def clear_joint_forces(self, req):
        with self._lock:
            self._world.clear_joint_forces(req.joint_name)
        return JointRequestResponse()

    # --- links ------------------------------------------------------------------------------

    def apply_body_wrench(self, req):
        res = ApplyBodyWrenchResponse()
        if not _finite(req.reference_point, req.wrench.force, req.wrench.torque):
            return refuse(res, 'ApplyBodyWrench: reference_point and wrench must be finite')
        point, force, torque = (Vec3(v.x, v.y, v.z) for v in
                                (req.reference_point, req.wrench.force, req.wrench.torque))
        with self._lock:
            applied = self._world.apply_body_wrench(
                req.body_name, req.reference_frame, point, force, torque,
                to_ns(req.start_time), to_ns(req.duration))
        if not applied.ok:
            return refuse(res, prefixed('ApplyBodyWrench', applied.message))
        return succeed(res, prefixed('ApplyBodyWrench', applied.message))

    def clear_body_wrenches(self, req):
        with self._lock:
            self._world.clear_body_wrenches(req.body_name)
        return BodyRequestResponse()

    def get_link_state(self, req):
        res = GetLinkStateResponse()
        with self._lock:
            found, _ = self._world.link_properties(req.link_name)
            if found.ok:
                state, pose, twist = self._world.link_state(req.link_name, req.reference_frame)
        if not found.ok:
            return refuse(res, 'GetLinkState: link not found, did you forget to scope the link '
                               'by model name?')
        if not state.ok:
            return refuse(res, prefixed('GetLinkState', state.message))
        res.link_state = LinkState(req.link_name, to_pose_msg(pose), to_twist_msg(twist),
                                   req.reference_frame)
        return succeed(res, 'GetLinkState: got state')

    def _apply_link_state(self, state):
        if not pose_is_finite(state.pose) or not twist_is_finite(state.twist):
            return Status.Error('SetLinkState: pose and twist must be finite')
        with self._lock:
            found, _ = self._world.link_properties(state.link_name)
            if found.ok:
                done = self._world.set_link_state(state.link_name, to_core_pose(state.pose),
                                                  to_core_twist(state.twist),
                                                  state.reference_frame)
        if not found.ok:
            return Status.Error('SetLinkState: link not found, did you forget to scope the link '
                                'by model name?')
        if not done.ok:
            return Status.Error(prefixed('SetLinkState', done.message))
        return Status.Ok('SetLinkState: success')

    def set_link_state(self, req):
        status = self._apply_link_state(req.link_state)
        res = SetLinkStateResponse()
        return succeed(res, status.message) if status.ok else refuse(res, status.message)

    def _set_link_state_topic(self, msg):
        status = self._apply_link_state(msg)
        if not status.ok:
            rospy.logwarn(status.message)

    def get_link_properties(self, req):
        res = GetLinkPropertiesResponse()
        with self._lock:
            found, link = self._world.link_properties(req.link_name)
        if not found.ok:
            return refuse(res, 'GetLinkProperties: link not found, did you forget to scope the '
                               'link by model name?')
        res.com = to_pose_msg(link.com)
        res.gravity_mode = link.gravity_mode
        res.mass = link.mass
        res.ixx, res.ixy, res.ixz = link.ixx, link.ixy, link.ixz
        res.iyy, res.iyz, res.izz = link.iyy, link.iyz, link.izz
        return succeed(res, 'GetLinkProperties: got properties')

    # --- models -----------------------------------------------------------------------------

    def spawn_urdf_model(self, req):
        return self._spawn_model(ModelFormat.URDF, req)

    def spawn_sdf_model(self, req):
        return self._spawn_model(ModelFormat.SDF, req)

    def _spawn_model(self, requested, req):
        """Either format on either service, told apart by the root element, as Gazebo; the
        service only names itself in the log line."""
        res = SpawnModelResponse()
        detected, model_format = detect_model_format(req.model_xml)
        if not detected.ok:
            return refuse(res, prefixed('SpawnModel', detected.message))
        if not pose_is_finite(req.initial_pose):
            return refuse(res, 'SpawnModel: initial_pose must be finite')
        with self._lock:
            spawned = self._world.spawn(req.model_name, req.model_xml, model_format,
                                        to_core_pose(req.initial_pose), req.reference_frame)
        if not spawned.ok:
            return refuse(res, prefixed('SpawnModel', spawned.message))
        rospy.loginfo("spawned model '%s' (%s) via %s", req.model_name, model_format.name,
                      'spawn_%s_model' % requested.value)
        return succeed(res, 'SpawnModel: Successfully spawned entity')

    def delete_model(self, req):
        res = DeleteModelResponse()
        with self._lock:
            deleted = self._world.delete_model(req.model_name)
        if not deleted.ok:
            return refuse(res, prefixed('DeleteModel', deleted.message))
        return succeed(res, 'DeleteModel: successfully deleted model')

    def get_model_state(self, req):
        res = GetModelStateResponse()
        with self._lock:
            now_ns = self._world.time_ns()
            state, pose, twist = self._world.model_state(req.model_name,
                                                         req.relative_entity_name)
        if not state.ok:
            return refuse(res, prefixed('GetModelState', state.message))
        res.header.stamp = from_ns(now_ns)
        res.header.frame_id = req.relative_entity_name
        res.pose = to_pose_msg(pose)
        res.twist = to_twist_msg(twist)
        return succeed(res, 'GetModelState: got properties')

    def _apply_model_state(self, state):
        if not pose_is_finite(state.pose) or not twist_is_finite(state.twist):
            return Status.Error('SetModelState: pose and twist must be finite')
        with self._lock:
            done = self._world.set_model_state(state.model_name, to_core_pose(state.pose),
                                               to_core_twist(state.twist), state.reference_frame)
        if not done.ok:
            return Status.Error(prefixed('SetModelState', done.message))
        return Status.Ok('SetModelState: set model state done')

    def set_model_state(self, req):
        status = self._apply_model_state(req.model_state)
        res = SetModelStateResponse()
        return succeed(res, status.message) if status.ok else refuse(res, status.message)

    def _set_model_state_topic(self, msg):
        status = self._apply_model_state(msg)
        if not status.ok:
            rospy.logwarn(status.message)

    def set_model_configuration(self, req):
        """urdf_param_name is ignored, as Gazebo does: the model already knows its joints."""
        res = SetModelConfigurationResponse()
        if len(req.joint_names) != len(req.joint_positions):
            return refuse(res, 'SetModelConfiguration: %d joint_names but %d joint_positions'
                          % (len(req.joint_names), len(req.joint_positions)))
        if not all(math.isfinite(p) for p in req.joint_positions):
            return refuse(res, 'SetModelConfiguration: joint_positions must be finite')
        with self._lock:
            if self._world.has_model(req.model_name):
                done = self._world.set_model_configuration(req.model_name, req.joint_names,
                                                           req.joint_positions)
            else:
                done = Status.Error('model [%s] does not exist' % req.model_name)
        if not done.ok:
            return refuse(res, prefixed('SetModelConfiguration', done.message))
        return succeed(res, 'SetModelConfiguration: success')

    def get_model_properties(self, req):
        res = GetModelPropertiesResponse()
        with self._lock:
            found, model = self._world.model_properties(req.model_name)
        if not found.ok:
            return refuse(res, prefixed('GetModelProperties', found.message))
        # Bare link names, as Gazebo answers (its srv comment says scoped, its code says bare).
        res.canonical_body_name = bare_name(model.canonical_link)
        res.body_names = [bare_name(link) for link in model.links]
        res.geom_names = model.geoms
        res.joint_names = model.joints
        res.is_static = model.is_static
        return succeed(res, 'GetModelProperties: got properties')

    def get_world_properties(self, req):
        res = GetWorldPropertiesResponse()
        with self._lock:
            res.sim_time = self._world.time()
            res.model_names = self._world.model_names()
        res.rendering_enabled = False  # there is no renderer
        return succeed(res, 'GetWorldProperties: got properties')

    # --- physics ----------------------------------------------------------------------------

    def get_physics_properties(self, req):
        """The message has no engine field, so the status says which engine runs. ode_config
        holds the solver settings as set; which of them bullet uses is said in
        BulletWorld._apply_params."""
        res = GetPhysicsPropertiesResponse()
        with self._lock:
            p = self._world.params()
            res.pause = self._paused
            res.max_update_rate = self._max_update_rate
        res.time_step = p.step
        res.gravity = Vector3(*p.gravity)
        ode = res.ode_config
        for field in ('auto_disable_bodies', 'sor_pgs_precon_iters', 'sor_pgs_iters',
                      'sor_pgs_w', 'sor_pgs_rms_error_tol', 'contact_surface_layer',
                      'contact_max_correcting_vel', 'cfm', 'erp', 'max_contacts'):
            setattr(ode, field, getattr(p, field))
        return succeed(res, 'GetPhysicsProperties: got properties (engine: %s)' % ENGINE)

    def set_physics_properties(self, req):
        res = SetPhysicsPropertiesResponse()
        if not math.isfinite(req.max_update_rate) or req.max_update_rate < 0:
            return refuse(res, 'SetPhysicsProperties: max_update_rate must be finite and >= 0 '
                               '(0 = as fast as possible), got %g' % req.max_update_rate)
        with self._lock:
            p = self._world.params()  # keeps what ODEPhysics can't say (quick_step)
            p.step = req.time_step
            p.gravity = Vec3(req.gravity.x, req.gravity.y, req.gravity.z)
            for field in ('auto_disable_bodies', 'sor_pgs_precon_iters', 'sor_pgs_iters',
                          'sor_pgs_w', 'sor_pgs_rms_error_tol', 'contact_surface_layer',
                          'contact_max_correcting_vel', 'cfm', 'erp', 'max_contacts'):
                setattr(p, field, getattr(req.ode_config, field))
            done = self._world.set_params(p)
            if done.ok:
                self._max_update_rate = req.max_update_rate
        if not done.ok:
            return refuse(res, prefixed('SetPhysicsProperties', done.message))
        return succeed(res, 'SetPhysicsProperties: physics properties set')

    def pause_physics(self, req):
        with self._lock:
            self._paused = True
        return EmptyResponse()

    def unpause_physics(self, req):
        with self._lock:
            self._paused = False
            self._unpaused.notify_all()
        return EmptyResponse()

    def reset_simulation(self, req):
        with self._lock:
            self._world.reset_simulation()
        return EmptyResponse()

    def reset_world(self, req):
        with self._lock:
            self._world.reset_world()
        return EmptyResponse()


def main(argv=None):
    """rosrun onedof_sim onedof_sim_bullet [-u] [-e bullet] [_param:=value ...]"""
    argv = sys.argv if argv is None else argv
    # The step loop holds the GIL while pybullet steps; a service thread waiting for it would get
    # it only after the default 5 ms switch interval. The controller makes two calls per 10 ms
    # of sim time: with 0.2 ms their latency on a loaded machine drops to the ODE node's.
    sys.setswitchinterval(GIL_SWITCH_INTERVAL)
    # rospy's own SIGINT handler shuts rospy down inside the interrupted main thread, which may
    # be inside Publisher.publish holding the lock its writer thread needs: the shutdown then
    # waits out rospy's 5 s join timeouts. Here the handler only asks the loop to stop, and
    # rospy shuts down after it, from plain code.
    stop = threading.Event()
    rospy.init_node('gazebo', disable_signals=True)
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    args = rospy.myargv(argv)[1:]  # without the ROS remappings (_param:=value)
    try:
        options = read_node_options(args)
        api = BulletGazeboApi(options)
    except OptionError as error:
        rospy.logfatal('onedof_sim (bullet): %s', error)
        rospy.signal_shutdown('invalid start-up option')
        return 1
    except ValueError as error:
        rospy.logfatal('onedof_sim (bullet): invalid physics parameters: %s', error)
        rospy.signal_shutdown('invalid physics parameters')
        return 1
    try:
        api.run(stop)
    finally:
        rospy.signal_shutdown('stopped')
        api.close()
    return 0
