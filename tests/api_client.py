"""A rospy client of the simulator's Gazebo API, shared by the end-to-end API tests.

Every service of /gazebo/ is an attribute (`api.get_joint_properties('joint1')`); the helpers below
are what the tests need on top: spawning the tutorial robot, sim time in integer nanoseconds (effort
windows are exact only on the step grid), and running the paused world for a known sim time.
"""
import math

from conftest import TUTORIAL_URDF
from onedof_harness.private_ros import wait_until
from onedof_sim.tutorial import physics

ROBOT = 'one_DOF_robot'
STEP_NS = 1000000  # the default 1 ms step

SERVICE_TYPES = {
    'get_joint_properties': 'GetJointProperties', 'apply_joint_effort': 'ApplyJointEffort',
    'clear_joint_forces': 'JointRequest', 'apply_body_wrench': 'ApplyBodyWrench',
    'clear_body_wrenches': 'BodyRequest', 'spawn_urdf_model': 'SpawnModel',
    'spawn_sdf_model': 'SpawnModel', 'delete_model': 'DeleteModel',
    'get_model_state': 'GetModelState', 'set_model_state': 'SetModelState',
    'get_link_state': 'GetLinkState', 'set_link_state': 'SetLinkState',
    'set_model_configuration': 'SetModelConfiguration',
    'get_model_properties': 'GetModelProperties', 'get_world_properties': 'GetWorldProperties',
    'get_link_properties': 'GetLinkProperties', 'get_physics_properties': 'GetPhysicsProperties',
    'set_physics_properties': 'SetPhysicsProperties', 'pause_physics': 'Empty',
    'unpause_physics': 'Empty', 'reset_simulation': 'Empty', 'reset_world': 'Empty',
    'set_joint_properties': 'SetJointProperties', 'set_link_properties': 'SetLinkProperties',
    'get_light_properties': 'GetLightProperties', 'set_light_properties': 'SetLightProperties',
    'delete_light': 'DeleteLight',
    # The simulator's own service beyond Gazebo's.
    'step_simulation': 'onedof_sim/StepSimulation',
}

# A free box (SDF), 0.2 m cube of 1 kg, for the model and link state services.
BOX_SDF = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="box">
    <link name="body">
      <inertial><mass>1</mass>
        <inertia><ixx>0.00667</ixx><iyy>0.00667</iyy><izz>0.00667</izz>
                 <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
      <collision name="collision"><geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision>
    </link>
  </model>
</sdf>
"""
BOX_VISUAL = ('<visual name="visual"><geometry><box><size>0.2 0.2 0.2</size></box></geometry>'
              '</visual>')


def tutorial_urdf():
    with open(TUTORIAL_URDF) as f:
        return f.read()


def pose(x=0.0, y=0.0, z=0.0):
    from geometry_msgs.msg import Pose
    p = Pose()
    p.position.x, p.position.y, p.position.z = x, y, z
    p.orientation.w = 1.0
    return p


def fixed_chain_sdf(links, name='chain'):
    """An SDF model of `links` links welded by fixed joints into one body: libsdformat takes
    seconds to read a thousand."""
    parts = ['<sdf version="1.6"><model name="%s">' % name]
    for i in range(links):
        parts.append('<link name="l%d"><pose>0 0 %g 0 0 0</pose><inertial><mass>1</mass><inertia>'
                     '<ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz><ixy>0</ixy><ixz>0</ixz>'
                     '<iyz>0</iyz></inertia></inertial></link>' % (i, 0.001 * i))
        if i:
            parts.append('<joint name="j%d" type="fixed"><parent>l%d</parent><child>l%d</child>'
                         '</joint>' % (i, i - 1, i))
    parts.append('</model></sdf>')
    return ''.join(parts)


def ros_time(ns):
    import rospy
    return rospy.Time(ns // 10 ** 9, ns % 10 ** 9)


def ros_duration(ns):
    import rospy
    return rospy.Duration(ns // 10 ** 9, ns % 10 ** 9)


FOREVER_NS = -10 ** 9  # any negative duration: until cleared


class GazeboApi:
    """Service proxies of /gazebo/* with the gazebo_msgs types, created on first use."""

    def __init__(self, rospy, namespace='/gazebo'):
        self._rospy = rospy
        self._namespace = namespace
        self._proxies = {}

    def __getattr__(self, name):
        if name not in SERVICE_TYPES:
            raise AttributeError(name)
        if name not in self._proxies:
            import importlib
            type_name = SERVICE_TYPES[name]
            package = 'std_srvs' if type_name == 'Empty' else 'gazebo_msgs'
            if '/' in type_name:
                package, type_name = type_name.split('/')
            module = importlib.import_module(package + '.srv')
            service = self._namespace + '/' + name
            self._rospy.wait_for_service(service, timeout=60)
            # Persistent: one connection, so that a call costs well under a millisecond.
            self._proxies[name] = self._rospy.ServiceProxy(service, getattr(module, type_name),
                                                           persistent=True)
        return self._proxies[name]

    # --- helpers ------------------------------------------------------------------------------
    def spawn_robot(self, name=ROBOT, initial_pose=None):
        res = self.spawn_urdf_model(name, tutorial_urdf(), '', initial_pose or pose(), '')
        assert res.success, res.status_message
        return res

    def spawn_box(self, name='box', initial_pose=None, visual=False):
        """A 0.2 m box of 1 kg: its collision, and with `visual` a visual of its shape (what the
        window draws, and a click selects)."""
        sdf = BOX_SDF.replace('</link>', BOX_VISUAL + '</link>') if visual else BOX_SDF
        res = self.spawn_sdf_model(name, sdf, '', initial_pose or pose(z=0.1), '')
        assert res.success, res.status_message
        return res

    def joint(self, name='joint1'):
        """(position, rate) of a joint."""
        res = self.get_joint_properties(name)
        assert res.success, res.status_message
        return res.position[0], res.rate[0]

    def sim_time_ns(self):
        """Sim time on the step grid (get_world_properties answers in float seconds)."""
        return int(round(self.get_world_properties().sim_time * 1e9))

    def set_physics(self, max_update_rate=None, gravity=None):
        """Sets the physics properties given, keeping the others."""
        physics = self.get_physics_properties()
        if max_update_rate is not None:
            physics.max_update_rate = max_update_rate
        if gravity is not None:
            physics.gravity.x, physics.gravity.y, physics.gravity.z = gravity
        res = self.set_physics_properties(physics.time_step, physics.max_update_rate,
                                          physics.gravity, physics.ode_config)
        assert res.success, res.status_message

    def set_gravity(self, x, y, z):
        self.set_physics(gravity=(x, y, z))

    def run_until(self, sim_ns, timeout=120):
        """Unpauses, waits until sim time reaches sim_ns, pauses; returns the sim time paused at."""
        self.unpause_physics()
        wait_until(lambda: self.sim_time_ns() >= sim_ns, timeout,
                   what='sim time %.3f s' % (sim_ns * 1e-9))
        self.pause_physics()
        return self.sim_time_ns()

    def run_for(self, duration_ns, timeout=120):
        return self.run_until(self.sim_time_ns() + duration_ns, timeout)


def pendulum_period(amplitude, mass=physics.MASS):
    """Period of link2 (of that mass, inertia about its COM unchanged) swinging about its lowest
    point, with the first amplitude correction."""
    inertia = physics.INERTIA_ABOUT_JOINT + (mass - physics.MASS) * physics.COM_DISTANCE ** 2
    small = 2 * math.pi * math.sqrt(inertia / (mass * physics.GRAVITY * physics.COM_DISTANCE))
    return small * (1 + amplitude ** 2 / 16)
