"""The `imu` sensor with libgazebo_ros_imu_sensor.so over real ROS, on every engine, on a cube of
our own making whose IMU link carries the sensor 5 cm ahead, turned a quarter about x
(tests/robots/imu_sensor_box.urdf). At rest it reads gravity's reaction up in the sensor's own
axes and no rates, its orientation is the sensor's (its pose on the link honoured) and follows a
set_model_state turn; spun about the vertical without gravity it reads the spin about its y axis
and the centripetal acceleration of its lever; two lock-step runs with noise publish the same
numbers; a malformed sensor is a clear error at spawn and the model spawns."""
import math
import os

from api_client import GazeboApi, pose
from conftest import GROUND, start_sim
from onedof_harness.private_ros import wait_until
from test_imu_ft import in_frame, listen as listen_to, step_and_hear

ROBOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'robots', 'imu_sensor_box.urdf')
TOPIC = '/imu_sensor_box/imu'  # no <robotNamespace>: the model's name, as in Gazebo
G = 9.81
LEVER = 0.05                   # the sensor ahead of its link's origin (x), which is the cube's top
QUARTER_X = (math.sin(math.pi / 4), 0.0, 0.0, math.cos(math.pi / 4))  # its turn on the link


def robot(noise=0.0, stddev_x=None):
    with open(ROBOT) as f:
        text = f.read()
    return text.replace('STDDEV_X', repr(noise) if stddev_x is None else stddev_x).replace(
        'NOISE', repr(noise))


def listen(ros, rospy):
    from sensor_msgs.msg import Imu
    return listen_to(ros, rospy, TOPIC, Imu)


def product(a, b):
    """Quaternion product a b, (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def assert_close(values, expected, tolerance, what):
    assert all(abs(a - b) <= tolerance for a, b in zip(values, expected)), (what, values, expected)


def assert_orientation(o, q, tolerance, what):
    sign = 1 if o.w * q[3] >= 0 else -1
    assert_close([sign * o.x, sign * o.y, sign * o.z, sign * o.w], q, tolerance, what)


def test_the_imu_sensor_at_rest_reads_gravity_in_its_own_axes_and_follows_a_turn(
        shared_sim, ros, rospy_client):
    from gazebo_msgs.msg import ModelState
    from geometry_msgs.msg import Pose, Quaternion, Point
    api = shared_sim
    api.set_gravity(0, 0, -G)
    spawned = api.spawn_urdf_model('imu_sensor_box', robot(), '', pose(z=0.1), '')
    assert spawned.success, spawned.status_message
    heard = listen(ros, rospy_client)

    msg = step_and_hear(api, heard, 1000, 1000000000)
    assert msg.header.frame_id == 'imu_sensor_frame'
    stamps = [m.header.stamp.to_nsec() for m in heard]
    assert stamps[0] % 10000000 == 0
    assert {b - a for a, b in zip(stamps, stamps[1:])} == {10000000}  # 100 Hz of sim time
    a, w = msg.linear_acceleration, msg.angular_velocity
    # The sensor's y axis is the link's z: gravity's reaction reads along +y.
    assert_close([a.x, a.y, a.z], [0, G, 0], 1e-3, 'acceleration at rest')
    assert_close([w.x, w.y, w.z], [0, 0, 0], 1e-3, 'rates at rest')
    assert_orientation(msg.orientation, QUARTER_X, 1e-4, 'orientation at rest: its pose')
    assert list(msg.orientation_covariance) == [0.0] * 9  # gaussianNoise 0

    # The cube turned 30 degrees about z, then a quarter about y: it lies on another face.
    yaw, pitch = math.radians(30), math.pi / 2
    turn = product((0, 0, math.sin(yaw / 2), math.cos(yaw / 2)),
                   (0, math.sin(pitch / 2), 0, math.cos(pitch / 2)))
    res = api.set_model_state(ModelState('imu_sensor_box',
                                         Pose(Point(0, 0, 0.1), Quaternion(*turn)), None, 'world'))
    assert res.success, res.status_message
    msg = step_and_hear(api, heard, 500, 1500000000)
    sensor = product(turn, QUARTER_X)
    assert_orientation(msg.orientation, sensor, 1e-3, 'turned orientation')
    a, w = msg.linear_acceleration, msg.angular_velocity
    up = in_frame(sensor, [0, 0, G])
    assert abs(up[0]) > 9  # the sensor's x axis is vertical now: the frames differ
    assert_close([a.x, a.y, a.z], up, 1e-3, 'turned acceleration at rest')
    assert_close([w.x, w.y, w.z], [0, 0, 0], 1e-3, 'turned rates at rest')


def test_spun_without_gravity_the_imu_sensor_reads_the_spin_and_its_levers_acceleration(
        shared_sim, ros, rospy_client):
    from gazebo_msgs.msg import ModelState
    from geometry_msgs.msg import Pose, Quaternion, Point, Twist, Vector3
    api = shared_sim
    api.set_gravity(0, 0, 0)
    spawned = api.spawn_urdf_model('imu_sensor_box', robot(), '', pose(z=1), '')
    assert spawned.success, spawned.status_message
    heard = listen(ros, rospy_client)
    spin = 2.0  # rad/s about the world's z, through the cube's centre
    res = api.set_model_state(ModelState('imu_sensor_box',
                                         Pose(Point(0, 0, 1), Quaternion(0, 0, 0, 1)),
                                         Twist(Vector3(0, 0, 0), Vector3(0, 0, spin)), 'world'))
    assert res.success, res.status_message
    msg = step_and_hear(api, heard, 200, 200000000)
    a, w = msg.linear_acceleration, msg.angular_velocity
    # The spin is about the link's z, the sensor's y.
    assert_close([w.x, w.y, w.z], [0, spin, 0], 1e-3, 'rates of the spin')
    # 5 cm from the axis along its x, it is pulled towards it: spin^2 r along its -x, within the
    # finite difference's lag of half an update's turn (1 %).
    assert_close([a.x, a.y, a.z], [-spin * spin * LEVER, 0, 0], 0.02 * spin * spin * LEVER,
                 'centripetal acceleration')


def record(ros, rospy, engine, noise):
    """A paused lock-step simulator of its own, the cube dropped from 20 cm, stepped 400 steps:
    the messages heard."""
    sim = start_sim(ros, engine, args=['_paused:=true', '_lockstep:=true'])
    api = GazeboApi(rospy)
    api.set_gravity(0, 0, -G)
    assert api.spawn_urdf_model('imu_sensor_box', robot(noise), '', pose(z=0.3), '').success
    heard = listen(ros, rospy)
    for end_ns in range(10000000, 400000001, 10000000):
        step_and_hear(api, heard, 10, end_ns)
    ros.terminate(sim)
    wait_until(lambda: not ros.has_service('/gazebo/unpause_physics'), 60,
               what='the stopped simulator to leave the graph')
    return [(m.header.stamp.to_nsec(), m.linear_acceleration, m.angular_velocity, m.orientation)
            for m in heard]


def test_two_lock_step_runs_of_the_imu_sensor_publish_the_same_numbers(ros, rospy_client, engine):
    first = record(ros, rospy_client, engine, 0.01)
    second = record(ros, rospy_client, engine, 0.01)
    assert len(first) == 40
    assert first == second
    assert any(abs(a.y - G) > 1 for _, a, _, _ in first)  # it fell and landed
    # The noise is there: rates at rest are not all exactly 0.
    assert any(w.x != 0 for _, _, w, _ in first)


def test_a_malformed_imu_sensor_is_a_clear_error_and_the_model_spawns(shared_sim, ros, engine):
    api = shared_sim
    bad_number = robot(stddev_x="'abc'")
    assert api.spawn_urdf_model('bad_noise', bad_number, '', pose(z=0.1), '').success
    no_frame = robot().replace('<frameName>imu_sensor_frame</frameName>', '')
    assert api.spawn_urdf_model('no_frame', no_frame, '', pose(x=2, z=0.1), '').success
    assert set(api.get_world_properties().model_names) == {GROUND, 'bad_noise', 'no_frame'}
    log = ros.log_text('sim_' + engine)
    assert ("libgazebo_ros_imu_sensor.so for model 'bad_noise': sensor 'imu_sensor' not started: "
            "<imu><angular_velocity><x><noise><stddev> is ''abc'', not a number") in log, log
    assert ("libgazebo_ros_imu_sensor.so for model 'no_frame': sensor 'imu_sensor' not started: "
            "missing <frameName>, which it needs") in log, log
