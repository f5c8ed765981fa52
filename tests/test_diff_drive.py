"""gazebo_ros_diff_drive and gazebo_ros_joint_state_publisher over real ROS, on every engine: a
base of our own making with the book's mobot's shape and plugin parameters
(tests/robots/drive_base.urdf) drives the twist commanded on cmd_vel, reports it on odom and TF
at sim time, its wheels' joints are on joint_states, and what the simulator ignores in it (a
sensor, an unknown plugin) is logged once, by name, at spawn; gazebo_ros_p3d reports its
base's ground truth. A small base whose wheel motors, at their torque bound, drag a caster that
slides (tests/robots/caster_base.urdf), spawned with spawn_model as a new user does, drives and
turns at its command."""
import math
import os

import pytest

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from gazebo_commands import output, run as run_command
from onedof_harness.private_ros import wait_until

ROBOTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'robots')
URDF = os.path.join(ROBOTS, 'drive_base.urdf')
CASTER_URDF = os.path.join(ROBOTS, 'caster_base.urdf')
LINEAR, ANGULAR = 0.5, 0.3  # the commanded twist: m/s, rad/s
DRIVE_S = 10.0               # seconds of sim time it is driven for
SETTLE_S = 2.0               # the start of the drive left out of the path's figures
CHUNK_STEPS = 500            # the true pose is sampled every 0.5 s of sim time
WHEELS = ('left_wheel_joint', 'right_wheel_joint')


def drive_base_urdf(odometry_source):
    with open(URDF) as f:
        return f.read().replace('ODOMETRY_SOURCE', odometry_source)


def yaw(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def unwrap(angles):
    out = [angles[0]]
    for angle in angles[1:]:
        out.append(out[-1] + math.remainder(angle - out[-1], 2 * math.pi))
    return out


class Drive:
    """What a drive of the base recorded: the true pose every 0.5 s of sim time (s, x, y, yaw),
    and the messages heard."""


def command_and_sample(api, rospy, model, linear, angular):
    """On a paused simulator with `model` spawned: settles it, commands the twist on cmd_vel and
    steps DRIVE_S of sim time from when its wheels turn, sampling its true pose. A Drive with
    samples, start_s, end_s and twist (the model's at the end)."""
    from geometry_msgs.msg import Twist
    # Settle on the casters and wheels, then command the twist (latched: it reaches the plugin's
    # subscriber whenever that connects) and step until the wheels turn: the drive starts there.
    assert api.step_simulation(500).success
    command = rospy.Publisher('/cmd_vel', Twist, queue_size=1, latch=True)
    twist = Twist()
    twist.linear.x, twist.angular.z = linear, angular
    command.publish(twist)

    def wheels_turn():
        assert api.step_simulation(10).success
        return all(abs(api.joint(name)[1]) > 0.1 for name in WHEELS)
    wait_until(wheels_turn, 60, what='the wheels to turn on the command')
    start_ns = api.sim_time_ns()

    samples = []  # (sim time s, x, y, yaw) of the true pose
    while api.sim_time_ns() < start_ns + DRIVE_S * 1e9:
        assert api.step_simulation(CHUNK_STEPS).success
        state = api.get_model_state(model, '')
        assert state.success, state.status_message
        p = state.pose
        samples.append((api.sim_time_ns() * 1e-9, p.position.x, p.position.y, yaw(p.orientation)))
    out = Drive()
    out.samples, out.start_s, out.end_s = samples, start_ns * 1e-9, samples[-1][0]
    out.twist = state.twist
    return out


def drive(ros, rospy, engine, odometry_source):
    """Spawns the base on a paused simulator, commands the twist and steps DRIVE_S of sim time
    from when its wheels turn."""
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import JointState
    from tf2_msgs.msg import TFMessage
    sim = start_sim(ros, engine, args=['-u'])
    api = GazeboApi(rospy)

    odometry, joint_states, transforms = [], [], []
    rospy.Subscriber('/odom', Odometry, odometry.append, queue_size=100000)
    rospy.Subscriber('/joint_states', JointState, joint_states.append, queue_size=100000)
    rospy.Subscriber('/tf', TFMessage, transforms.append, queue_size=100000)
    ground_truth = []
    rospy.Subscriber('/ground_truth', Odometry, ground_truth.append, queue_size=100000)
    spawned = api.spawn_urdf_model('drive_base', drive_base_urdf(odometry_source), '', pose(), '')
    assert spawned.success, spawned.status_message

    out = command_and_sample(api, rospy, 'drive_base', LINEAR, ANGULAR)
    out.sim = sim
    out.odometry, out.joint_states = odometry, joint_states
    out.transforms, out.ground_truth = transforms, ground_truth
    return out


def steady_path(run):
    """The true path past the start-up: its length (m), duration (s) and the heading it turned
    through (rad)."""
    steady = [s for s in run.samples if s[0] >= run.start_s + SETTLE_S]
    headings = unwrap([s[3] for s in steady])
    arc = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(steady, steady[1:]))
    return arc, steady[-1][0] - steady[0][0], headings[-1] - headings[0]


def path_figures(run):
    """Speed, turn rate and radius of the true path past the start-up, and their text."""
    arc, duration, turned = steady_path(run)
    speed, turn_rate, radius = arc / duration, turned / duration, arc / turned
    figures = 'speed %.4f m/s, turn rate %.4f rad/s, radius %.4f m' % (speed, turn_rate, radius)
    return speed, turn_rate, radius, turned, figures


# A cylinder wheel lying on the ground touches it along a line, which the engines resolve as one
# (src/onedof_sim/src/core/engines: ODE with its force and friction across the wheel's width,
# Bullet with its resultant at its middle); ODE takes a step whose exact LCP fails again with its
# iterative solver, so no solver warning is logged. The odometry source changes what odom
# reports, not the drive: each drive is checked for both.
@pytest.mark.parametrize('engine,odometry_source', [
    (engine, source) for engine in ENGINES for source in ('world', 'encoder')])
def test_a_diff_drive_base_drives_the_commanded_twist_and_reports_it(
        ros, rospy_client, engine, odometry_source):
    run = drive(ros, rospy_client, engine, odometry_source)
    samples, end_s = run.samples, run.end_s
    odometry, joint_states, transforms = run.odometry, run.joint_states, run.transforms
    ground_truth = run.ground_truth
    speed, turn_rate, radius, turned, figures = path_figures(run)
    print('%s, %s odometry: %s' % (engine, odometry_source, figures))

    # The true path: the commanded twist within 5 %, with no solver warning.
    assert speed == pytest.approx(LINEAR, rel=0.05), figures
    assert turn_rate == pytest.approx(ANGULAR, rel=0.05), figures
    assert radius == pytest.approx(LINEAR / ANGULAR, rel=0.05), figures
    assert 'LCP' not in ros.log_text(run.sim)

    # Odometry at the last update: within 2 % of the distance travelled of the true pose then.
    # The true pose is read at the end; the last odometry is at most one update period (10 ms)
    # older, and the base moves 5 mm in it.
    wait_until(lambda: odometry and odometry[-1].header.stamp.to_sec() >= end_s - 0.011, 30,
               what='the odometry of the last update')
    last = odometry[-1]
    travelled = math.hypot(samples[-1][1], samples[-1][2])
    path = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(samples, samples[1:]))
    error = math.hypot(last.pose.pose.position.x - samples[-1][1],
                       last.pose.pose.position.y - samples[-1][2])
    print('%s, %s odometry: %.4f m from the true pose after %.3f m (%.2f %%)' % (
        engine, odometry_source, error, path, 100 * error / path))
    assert error <= 0.02 * path, (error, path, travelled)
    assert abs(math.remainder(yaw(last.pose.pose.orientation) - samples[-1][3], 2 * math.pi)) \
        <= 0.02 * turned
    assert (last.header.frame_id, last.child_frame_id) == ('odom', 'base_link')
    # Stamped in sim time, at the update rate (100 Hz): on its 10 ms grid (the publisher keeps
    # one message, as Gazebo's, so a subscriber may miss some while the world steps fast).
    stamps = [m.header.stamp.to_nsec() for m in odometry[-50:]]
    assert all(b > a and (b - a) % 10 ** 7 == 0 for a, b in zip(stamps, stamps[1:])), stamps

    # TF: odom -> base_link, and each wheel in base_link (publishWheelTF).
    pairs = {(t.header.frame_id, t.child_frame_id) for m in transforms for t in m.transforms}
    assert {('odom', 'base_link'), ('base_link', 'left_wheel'),
            ('base_link', 'right_wheel')} <= pairs, pairs

    # joint_states: the joint-state publisher's four joints (and the diff drive's wheels), in sim
    # time, the wheels as far as they have turned then.
    wait_until(lambda: any(len(m.name) == 4 for m in joint_states), 30,
               what="the joint-state publisher's message")
    published = [m for m in joint_states if len(m.name) == 4][-1]
    assert list(published.name) == ['left_wheel_joint', 'right_wheel_joint',
                                    'caster_swivel_left', 'caster_swivel_right']
    assert published.header.stamp.to_sec() <= end_s
    for index, name in enumerate(WHEELS):  # each wheel has turned over 10 rad by then
        assert published.position[index] > 10.0, (name, published.position)

    # p3d: base_link's ground truth in the world at 50 Hz, as the true pose at its stamp (the base
    # moves at most 0.5 m/s between that and the end).
    wait_until(lambda: ground_truth and ground_truth[-1].header.stamp.to_sec() >= end_s - 0.021,
               30, what='the ground truth of the last update')
    truth = ground_truth[-1]
    lag = end_s - truth.header.stamp.to_sec()
    assert truth.header.frame_id == 'world' and truth.child_frame_id == 'base_link'
    assert math.hypot(truth.pose.pose.position.x - samples[-1][1],
                      truth.pose.pose.position.y - samples[-1][2]) <= 0.5 * lag + 1e-3

    log = ros.log_text(run.sim)
    assert log.count('libgazebo_ros_not_simulated_here.so') == 1, log
    assert log.count("sensor 'base_sonar' (type sonar)") == 1, log


# The caster base (tests/robots/caster_base.urdf) spawned as a new user spawns it, with
# spawn_model from its file. Its wheel motors push with at most 5 N m each, 100 N at the rims in
# all, against the 67 N its sliding caster drags with: the base reaches the speed its wheels turn
# at, forward, and turns at their rate, on every engine.
def drive_caster_base(ros, rospy, engine, angular):
    sim = start_sim(ros, engine, args=['-u'])
    # The timeout only bounds a failure: on a loaded machine rosrun and spawn_model take minutes.
    result = run_command(ros, 'rosrun', 'gazebo_ros', 'spawn_model', '-file', CASTER_URDF,
                         '-urdf', '-model', 'caster_base', '-z', '0.1', timeout=600)
    assert result.returncode == 0, output(result)
    out = command_and_sample(GazeboApi(rospy), rospy, 'caster_base', LINEAR, angular)
    out.sim = sim
    return out


@pytest.mark.parametrize('engine', ENGINES)
def test_a_base_dragging_a_sliding_caster_drives_at_its_command(ros, rospy_client, engine):
    caster = drive_caster_base(ros, rospy_client, engine, 0.0)
    arc, duration, turned = steady_path(caster)
    first, last = caster.samples[0], caster.samples[-1]
    along = (math.cos(first[3]), math.sin(first[3]))  # its heading at the first sample
    forward = (last[1] - first[1]) * along[0] + (last[2] - first[2]) * along[1]
    final_speed = caster.twist.linear.x * along[0] + caster.twist.linear.y * along[1]
    figures = ('%s: %.4f m forward in %.1f s, %.4f m/s past the start-up, %.4f m/s at the end, '
               'turned %.4f rad' % (engine, forward, last[0] - first[0], arc / duration,
                                    final_speed, turned))
    print(figures)
    assert arc / duration == pytest.approx(LINEAR, rel=0.02), figures
    assert final_speed == pytest.approx(LINEAR, rel=0.02), figures
    assert forward == pytest.approx(LINEAR * (last[0] - first[0]), rel=0.02), figures
    assert abs(turned) < 0.02, figures
    assert 'LCP' not in ros.log_text(caster.sim)


@pytest.mark.parametrize('engine', ENGINES)
def test_a_base_dragging_a_sliding_caster_turns_at_its_command(ros, rospy_client, engine):
    caster = drive_caster_base(ros, rospy_client, engine, ANGULAR)
    speed, turn_rate, radius, turned, figures = path_figures(caster)
    figures = '%s: %s' % (engine, figures)
    print(figures)
    assert speed == pytest.approx(LINEAR, rel=0.02), figures
    assert turn_rate == pytest.approx(ANGULAR, rel=0.05), figures
    assert radius == pytest.approx(LINEAR / ANGULAR, rel=0.05), figures
    assert 'LCP' not in ros.log_text(caster.sim)
