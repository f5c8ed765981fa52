"""The laser over real ROS, on every engine: libgazebo_ros_gpu_laser.so on a gpu_ray sensor and
libgazebo_ros_laser.so on a ray sensor, on a base of our own making that carries a lidar as the
book's mobot does (tests/robots/laser_bot.urdf). Facing a box at a known distance it reports it
within 1 mm, +inf (Gazebo's out-of-range value) where there is nothing, Gazebo's LaserScan fields
in its frame at 40 Hz of sim time; in lock-step two runs publish the same scans, noise and a
falling ball in them; malformed sensors are logged once, by name, and the rest goes on."""
import math
import os

import pytest

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from onedof_harness.private_ros import wait_until

URDF = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'robots', 'laser_bot.urdf')
STEP_NS = 1000000       # the default 1 ms step
PERIOD_STEPS = 25       # 40 Hz
SAMPLES = 721
MIN_ANGLE, MAX_ANGLE = -1.570796, 1.570796
LIDAR_X = 0.2           # the lidar's x in the world (the base is welded at the origin)
FACE_X, HALF_WIDTH = 2.2, 0.25  # the box's near face, 2 m ahead of the lidar, and half its width
LASERS = [('gpu_ray', 'libgazebo_ros_gpu_laser.so'), ('ray', 'libgazebo_ros_laser.so')]

BOX_SDF = """<sdf version="1.6"><model name="wall"><static>true</static><link name="link">
<collision name="collision"><geometry><box><size>0.5 0.5 0.5</size></box></geometry></collision>
</link></model></sdf>"""
BALL_SDF = """<sdf version="1.6"><model name="ball"><link name="link"><inertial><mass>0.5</mass>
<inertia><ixx>0.002</ixx><iyy>0.002</iyy><izz>0.002</izz></inertia></inertial>
<collision name="collision"><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
</link></model></sdf>"""


def laser_bot_urdf(sensor_type, plugin, noise_stddev):
    with open(URDF) as f:
        return (f.read().replace('SENSOR_TYPE', sensor_type).replace('PLUGIN_FILE', plugin)
                .replace('NOISE_STDDEV', repr(noise_stddev)))


def record(ros, rospy, engine, laser, noise_stddev, scans, ball=False):
    """Starts a paused lock-step simulator, spawns the base and the box (and the ball, dropped
    through the scan's plane), and steps one scan period at a time: the scans heard, one each."""
    from sensor_msgs.msg import LaserScan
    sim = start_sim(ros, engine, args=['_paused:=true', '_lockstep:=true'])
    api = GazeboApi(rospy)
    heard = []
    subscriber = rospy.Subscriber('/scan', LaserScan, heard.append, queue_size=1000)
    spawned = api.spawn_urdf_model('laser_bot', laser_bot_urdf(*laser, noise_stddev), '',
                                   pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('wall', BOX_SDF, '', pose(FACE_X + HALF_WIDTH, 0, 0.25), '')
    assert spawned.success, spawned.status_message
    if ball:
        spawned = api.spawn_sdf_model('ball', BALL_SDF, '', pose(1.2, 0, 0.9), '')
        assert spawned.success, spawned.status_message
    # Connected as this simulator says: the subscriber's own count can still hold its
    # connection to the simulator of the run before.
    wait_until(lambda: ros.connected('/gazebo', '/scan', rospy.get_name()), 30,
               what='/scan to connect')
    for count in range(1, scans + 1):
        assert api.step_simulation(PERIOD_STEPS).success
        wait_until(lambda: len(heard) >= count, 30, what='scan %d' % count)
    assert len(heard) == scans
    subscriber.unregister()
    return sim, heard


def angle(i):
    return MIN_ANGLE + i * (MAX_ANGLE - MIN_ANGLE) / (SAMPLES - 1)


@pytest.mark.parametrize('engine', ENGINES)
@pytest.mark.parametrize('laser', LASERS, ids=[sensor for sensor, _ in LASERS])
def test_a_laser_facing_a_box_reports_it_within_a_millimetre_and_inf_where_nothing_is(
        ros, rospy_client, engine, laser):
    sim, scans = record(ros, rospy_client, engine, laser, 0.0, 2)
    for number, scan in enumerate(scans, 1):
        assert scan.header.stamp.to_nsec() == number * PERIOD_STEPS * STEP_NS
    scan = scans[-1]
    assert scan.header.frame_id == 'lidar_link'
    assert scan.angle_min == pytest.approx(MIN_ANGLE, abs=1e-6)
    assert scan.angle_max == pytest.approx(MAX_ANGLE, abs=1e-6)
    assert scan.angle_increment == pytest.approx((MAX_ANGLE - MIN_ANGLE) / (SAMPLES - 1), rel=1e-6)
    assert (scan.time_increment, scan.scan_time) == (0.0, 0.0)
    assert scan.range_min == pytest.approx(0.10, abs=1e-6)
    assert scan.range_max == pytest.approx(30.0, abs=1e-6)
    assert len(scan.ranges) == SAMPLES and list(scan.intensities) == [0.0] * SAMPLES

    distance = FACE_X - LIDAR_X
    assert abs(scan.ranges[SAMPLES // 2] - distance) <= 1e-3, scan.ranges[SAMPLES // 2]
    on_box = 0
    for i, reading in enumerate(scan.ranges):
        lateral = abs(distance * math.tan(angle(i)))
        if lateral < HALF_WIDTH - 0.005:  # on the face, clear of its edges
            assert abs(reading - distance / math.cos(angle(i))) <= 1e-3, (i, reading)
            on_box += 1
        elif lateral > HALF_WIDTH + 0.005:  # past the box: nothing within 30 m
            assert reading == math.inf, (i, reading)
    assert on_box > 40

    log = ros.log_text(sim)
    assert log.count("sensor 'empty_range' not started: <range> is min 1") == 1, log
    assert log.count("sensor 'nowhere' is ignored, with its plugins: its link 'no_such_link' is "
                     "not a link of the model") == 1, log
    assert log.count("Failed to load plugin libvendor_lidar_driver.so (plugin "
                     "'vendor_controller' of sensor 'vendor'): this simulator has no such plugin") \
        == 1, log


@pytest.mark.parametrize('engine', ENGINES)
def test_two_lockstep_runs_publish_identical_scans(ros, rospy_client, engine):
    runs = []
    for _ in range(2):
        sim, scans = record(ros, rospy_client, engine, LASERS[0], 0.01, 40, ball=True)
        ros.terminate(sim)
        runs.append([(scan.header.stamp.to_nsec(), tuple(scan.ranges)) for scan in scans])
    assert runs[0] == runs[1]
    # The scans are not all alike: the noise draws each range anew, and the ball falls through
    # the scan's plane 1 m ahead (1.0 m from the lidar, where the box is 2 m away).
    centre = SAMPLES // 2
    assert len({ranges[centre] for _, ranges in runs[0]}) > 10
    assert any(abs(ranges[centre] - 0.9) < 0.05 for _, ranges in runs[0])
    assert all(abs(ranges[centre] - 2.0) < 0.05 or abs(ranges[centre] - 0.9) < 0.15
               for _, ranges in runs[0])
