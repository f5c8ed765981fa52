"""gazebo_ros_imu and gazebo_ros_ft_sensor over real ROS, on every engine, on robots of our own
making with the book's sensors and parameters: a box carrying the mobot's IMU link
(tests/robots/imu_box.urdf) and the book's force-torque joint under a load
(tests/robots/ft_rig.urdf). The IMU at rest reads gravity up and no rates, its orientation follows
a set_model_state turn; the force-torque sensor reads the load's weight; two runs of the same
steps publish the same messages, noise included; a sensor the simulator cannot give is a clear
error at spawn and the model spawns."""
import math
import os

from api_client import GazeboApi, pose
from conftest import GROUND, start_sim
from onedof_harness.private_ros import wait_until

ROBOTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'robots')
G = 9.81
LOAD_KG = 2.01  # the load and the sensor link below the force-torque joint


def robot(name, noise=0.0):
    with open(os.path.join(ROBOTS, name + '.urdf')) as f:
        return f.read().replace('NOISE', repr(noise))


def listen(ros, rospy, topic, message_type):
    """A subscriber keeping every message, once the running simulator says it is connected: the
    subscriber's own count can still hold its connection to a simulator stopped before."""
    heard = []
    rospy.Subscriber(topic, message_type, heard.append, queue_size=100000)
    wait_until(lambda: ros.connected('/gazebo', topic, rospy.get_name()), 30,
               what='the simulator\'s %s to connect' % topic)
    return heard


def step_and_hear(api, heard, steps, stamp_ns):
    """Steps the paused world and waits for the message stamped `stamp_ns` (the last update due)."""
    assert api.step_simulation(steps).success
    wait_until(lambda: heard and heard[-1].header.stamp.to_nsec() >= stamp_ns, 30,
               what='the message stamped %d ns' % stamp_ns)
    return heard[-1]


def in_frame(q, v):
    """v (world) in the axes of a frame turned by the quaternion q (x, y, z, w)."""
    x, y, z, w = q
    # Rotate by the conjugate: R(q)^T v.
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    return [sum(r[row][i] * v[row] for row in range(3)) for i in range(3)]


def assert_close(values, expected, tolerance, what):
    assert all(abs(a - b) <= tolerance for a, b in zip(values, expected)), (what, values, expected)


def test_the_imu_at_rest_reads_gravity_up_and_follows_a_set_model_state_turn(shared_sim, ros,
                                                                               rospy_client):
    from gazebo_msgs.msg import ModelState
    from geometry_msgs.msg import Pose, Quaternion, Point
    from sensor_msgs.msg import Imu
    api = shared_sim
    api.set_gravity(0, 0, -G)
    spawned = api.spawn_urdf_model('imu_box', robot('imu_box'), '', pose(z=0.1), '')
    assert spawned.success, spawned.status_message
    heard = listen(ros, rospy_client, '/imu_data', Imu)

    msg = step_and_hear(api, heard, 1000, 990000000)
    assert msg.header.frame_id == 'imu_link'
    stamps = [m.header.stamp.to_nsec() for m in heard]
    assert {b - a for a, b in zip(stamps, stamps[1:])} == {10000000}  # 100 Hz of sim time
    a, w = msg.linear_acceleration, msg.angular_velocity
    assert_close([a.x, a.y, a.z], [0, 0, G], 1e-3, 'acceleration at rest')
    assert_close([w.x, w.y, w.z], [0, 0, 0], 1e-3, 'rates at rest')
    o = msg.orientation
    assert_close([o.x, o.y, o.z, o.w], [0, 0, 0, 1], 1e-4, 'orientation at rest')
    assert list(msg.linear_acceleration_covariance) == [0.0] * 9  # gaussianNoise 0

    # Turned a quarter about x, then 30 degrees about z: the cube lies on another face.
    roll, yaw = math.pi / 2, math.radians(30)
    cr, sr, cy, sy = math.cos(roll / 2), math.sin(roll / 2), math.cos(yaw / 2), math.sin(yaw / 2)
    q = (cy * sr, sy * sr, sy * cr, cy * cr)  # Rz(yaw) Rx(roll)
    turned = Pose(Point(0, 0, 0.1), Quaternion(*q))
    res = api.set_model_state(ModelState('imu_box', turned, None, 'world'))
    assert res.success, res.status_message
    msg = step_and_hear(api, heard, 500, 1490000000)
    o = msg.orientation
    sign = 1 if o.w * q[3] >= 0 else -1
    assert_close([sign * o.x, sign * o.y, sign * o.z, sign * o.w], q, 1e-3, 'turned orientation')
    a, w = msg.linear_acceleration, msg.angular_velocity
    up = in_frame(q, [0, 0, G])  # gravity's reaction, in the turned sensor's axes
    assert abs(up[1]) > 9  # the sensor's y axis points up now: the test tells the frames apart
    assert_close([a.x, a.y, a.z], up, 1e-3, 'turned acceleration at rest')
    assert_close([w.x, w.y, w.z], [0, 0, 0], 1e-3, 'turned rates at rest')


def test_the_force_torque_sensor_reads_the_static_loads_weight(shared_sim, ros, rospy_client):
    from geometry_msgs.msg import WrenchStamped
    api = shared_sim
    api.set_gravity(0, 0, -G)
    spawned = api.spawn_urdf_model('ft_rig', robot('ft_rig'), '', pose(), '')
    assert spawned.success, spawned.status_message
    heard = listen(ros, rospy_client, '/ft_sensor_topic', WrenchStamped)
    msg = step_and_hear(api, heard, 1000, 1000000000)
    assert msg.header.frame_id == 'ft_sensor_link'
    f, t = msg.wrench.force, msg.wrench.torque
    weight = LOAD_KG * G
    # What the load puts on the sensor: its weight, down, in the sensor link's axes.
    assert abs(f.z + weight) <= 0.01 * weight, (f, weight)
    assert math.hypot(f.x, f.y) <= 0.01 * weight, f
    assert math.sqrt(t.x ** 2 + t.y ** 2 + t.z ** 2) <= 0.01 * weight * 0.1, t


def record(ros, rospy, engine, noise):
    """A simulator of its own, paused, with both robots spawned (the box 20 cm up, to fall),
    stepped 600 steps: the IMU's and the sensor's messages from 0.1 s of sim time on. Each run
    has its own process, as two runs of the simulator are: ODE retakes a step its exact solver
    fails with its iterative one, whose random constraint order goes on from where the process's
    last such step left it."""
    from geometry_msgs.msg import WrenchStamped
    from sensor_msgs.msg import Imu
    sim = start_sim(ros, engine, args=['-u'])
    api = GazeboApi(rospy)
    api.set_gravity(0, 0, -G)
    assert api.spawn_urdf_model('imu_box', robot('imu_box', noise), '', pose(z=0.3), '').success
    assert api.spawn_urdf_model('ft_rig', robot('ft_rig', noise), '', pose(x=2), '').success
    imu = listen(ros, rospy, '/imu_data', Imu)
    ft = listen(ros, rospy, '/ft_sensor_topic', WrenchStamped)
    # In steps of 10, each heard before the next: stepped flat out, the publishers' queues
    # would drop messages before they are written out.
    for end_ns in range(10000000, 600000001, 10000000):
        step_and_hear(api, ft, 10, end_ns)
    wait_until(lambda: imu and imu[-1].header.stamp.to_nsec() >= 590000000, 30,
               what='the last IMU message')
    ros.terminate(sim)
    wait_until(lambda: not ros.has_service('/gazebo/unpause_physics'), 60,
               what='the stopped simulator to leave the graph')
    keep = lambda msgs: [m for m in msgs if m.header.stamp.to_nsec() >= 100000000]
    return ([(m.header.stamp.to_nsec(), m.linear_acceleration, m.angular_velocity, m.orientation)
             for m in keep(imu)],
            [(m.header.stamp.to_nsec(), m.wrench) for m in keep(ft)])


def test_two_runs_publish_the_same_sensor_data(ros, rospy_client, engine):
    first = record(ros, rospy_client, engine, 0.01)
    second = record(ros, rospy_client, engine, 0.01)
    assert (len(first[0]), len(first[1])) == (50, 501)
    assert first == second
    # The box fell 20 cm and landed: the IMU saw it move, so equal runs are not equal by
    # standing still.
    assert any(abs(a.z - G) > 1 for _, a, _, _ in first[0])


def test_a_sensor_that_cannot_be_given_is_a_clear_error_and_the_model_spawns(
        shared_sim, ros, engine):
    api = shared_sim
    fixed = robot('ft_rig').replace('type="prismatic"', 'type="fixed"')
    assert api.spawn_urdf_model('fixed_ft', fixed, '', pose(), '').success
    nobody = robot('imu_box').replace('<bodyName>imu_link', '<bodyName>no_such_link')
    assert api.spawn_urdf_model('lost_imu', nobody, '', pose(x=2, z=0.1), '').success
    assert set(api.get_world_properties().model_names) == {GROUND, 'fixed_ft', 'lost_imu'}
    log = ros.log_text('sim_' + engine)
    assert ("libgazebo_ros_ft_sensor.so for model 'fixed_ft' not started: jointName: "
            "ft_sensor_jnt is a fixed joint") in log, log
    assert ("libgazebo_ros_imu.so for model 'lost_imu' not started: bodyName: no_such_link "
            "does not exist") in log, log
