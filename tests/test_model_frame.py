"""Model frames over real ROS, on every engine: a model's pose in get/set_model_state, on
/gazebo/model_states, in a reference_frame and in diff drive's odometry is its model frame's, its
links keep their poses in it. A pioneer2dx shaped as Gazebo's (tests/robots/pioneer2dx.sdf: its
chassis 0.16 m above its model frame, the wheels' axles 0.11 m) set at (3, 3, 0) rests on its
wheels and drives; upstream's set_model_state_test scenario (gazebo_plugins/test/
set_model_state_test) passes on it. An SDF's own <pose> is taken in spawn_model's -x/-y/-z pose,
as gazebo_ros' spawn services compose them."""
import math
import os

import pytest

from api_client import pose
from conftest import WORKSPACE
from onedof_harness.private_ros import wait_until

PIONEER = os.path.join(WORKSPACE, 'tests', 'robots', 'pioneer2dx.sdf')
CHASSIS_HEIGHT, AXLE_HEIGHT = 0.16, 0.11
WHEELS = ('pioneer2dx::left_wheel', 'pioneer2dx::right_wheel')
ROUND_TRIP = 1e-9


@pytest.fixture
def api(shared_sim):
    """The module's simulator of each engine, paused, empty (conftest's shared_sim)."""
    return shared_sim


def pioneer_sdf():
    with open(PIONEER) as f:
        return f.read()


def wall_sdf(own_pose):
    """A static wall whose model has the <pose> own_pose, its one link at the model frame."""
    return ('<?xml version="1.0"?><sdf version="1.6"><model name="wall"><static>true</static>'
            '<pose>%s</pose><link name="link"><collision name="collision"><geometry><box>'
            '<size>0.2 2 1</size></box></geometry></collision></link></model></sdf>' % own_pose)


def turned(p, yaw):
    p.orientation.w, p.orientation.z = math.cos(yaw / 2), math.sin(yaw / 2)
    return p


def yaw_of(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def xyz(p):
    return p.position.x, p.position.y, p.position.z


def quaternion(p):
    return p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z


def spawn_pioneer(api, at=None):
    res = api.spawn_sdf_model('pioneer2dx', pioneer_sdf(), '', at or pose(), '')
    assert res.success, res.status_message


def model_pose(api, name, frame=''):
    res = api.get_model_state(name, frame)
    assert res.success, res.status_message
    return res.pose


def link_state(api, name, frame=''):
    res = api.get_link_state(name, frame)
    assert res.success, res.status_message
    return res.link_state


def set_model_state(api, name, p, frame, twist=None):
    from gazebo_msgs.msg import ModelState
    res = api.set_model_state(ModelState(name, p, twist, frame))
    assert (res.success, res.status_message) == (True, 'SetModelState: set model state done')


def test_model_state_and_topics_report_the_model_frame(api, rospy_client):
    from gazebo_msgs.msg import LinkStates, ModelStates
    spawn_pioneer(api, pose(1.0, 2.0))
    assert xyz(model_pose(api, 'pioneer2dx')) == pytest.approx((1, 2, 0), abs=1e-12)
    chassis = link_state(api, 'pioneer2dx::chassis').pose
    assert xyz(chassis) == pytest.approx((1, 2, CHASSIS_HEIGHT), abs=1e-12)
    # A link in its model's frame: its pose in the model.
    in_model = link_state(api, 'pioneer2dx::left_wheel', 'pioneer2dx').pose
    assert xyz(in_model) == pytest.approx((0.1, 0.17, AXLE_HEIGHT), abs=1e-12)
    models, links = [], []
    rospy_client.Subscriber('/gazebo/model_states', ModelStates, models.append, queue_size=10)
    rospy_client.Subscriber('/gazebo/link_states', LinkStates, links.append, queue_size=10)

    def heard():
        assert api.step_simulation(10).success
        return models and links
    wait_until(heard, 60, what='/gazebo/model_states and /gazebo/link_states')
    frame = models[-1].pose[models[-1].name.index('pioneer2dx')]
    assert xyz(frame) == pytest.approx((1, 2, 0), abs=2e-3)
    chassis = links[-1].pose[links[-1].name.index('pioneer2dx::chassis')]
    assert xyz(chassis) == pytest.approx((1, 2, CHASSIS_HEIGHT), abs=2e-3)


def test_set_and_get_model_state_round_trip_with_links_offset_from_the_frame(api):
    from geometry_msgs.msg import Twist, Vector3
    spawn_pioneer(api, pose(z=1.0))
    target = pose(1.5, -2.0, 0.7)
    s = math.sin(0.4)  # 0.8 rad about the oblique axis (2, -1, 2) / 3
    target.orientation.w, target.orientation.x = math.cos(0.4), s * 2 / 3
    target.orientation.y, target.orientation.z = -s / 3, s * 2 / 3
    twist = Twist(Vector3(0.3, -0.2, 0.1), Vector3(0.1, 0.2, -0.3))
    wall = api.spawn_sdf_model('wall', wall_sdf('0 0 1 0 0 1.5707963267948966'), '',
                               pose(x=2.0), '')
    assert wall.success, wall.status_message
    for frame in ('', 'wall', 'world'):
        set_model_state(api, 'pioneer2dx', target, frame, twist)
        got = api.get_model_state('pioneer2dx', frame)
        assert got.success, got.status_message
        assert xyz(got.pose) == pytest.approx(xyz(target), abs=ROUND_TRIP), frame
        assert quaternion(got.pose) == pytest.approx(quaternion(target), abs=ROUND_TRIP), frame
        for field in ('linear', 'angular'):
            sent, back = getattr(twist, field), getattr(got.twist, field)
            assert (back.x, back.y, back.z) == pytest.approx((sent.x, sent.y, sent.z),
                                                             abs=ROUND_TRIP), (frame, field)
    # Set in the wall's frame: in the world, the wall's frame (2, 0, 1), turned a quarter about
    # z, then the target.
    set_model_state(api, 'pioneer2dx', target, 'wall', twist)
    assert xyz(model_pose(api, 'pioneer2dx')) == pytest.approx((4.0, 1.5, 1.7), abs=ROUND_TRIP)


def test_pioneer_set_at_3_3_0_rests_on_its_wheels_and_drives(api, rospy_client):
    """Set at (3, 3, 0) it stands on its wheels, its chassis 0.16 m up (set with its chassis
    there, its wheels were buried and the engine threw it 21 m up), and drives on cmd_vel. The
    bounds are core_test's (PioneerSetAtThreeThreeRestsOnItsWheelsAndDrives), which says why
    Bullet needs them wider than ODE: it kicks the resting robot now and then."""
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    spawn_pioneer(api)
    assert api.step_simulation(300).success
    heading = 0.7
    set_model_state(api, 'pioneer2dx', turned(pose(3.0, 3.0, 0.0), heading), 'world')
    assert xyz(model_pose(api, 'pioneer2dx')) == pytest.approx((3, 3, 0), abs=ROUND_TRIP)
    chassis = link_state(api, 'pioneer2dx::chassis').pose
    assert xyz(chassis) == pytest.approx((3, 3, CHASSIS_HEIGHT), abs=ROUND_TRIP)
    # Where their joints have turned them since the spawn: Gazebo's model pitches the wheels by
    # 1.5707, so their axles pass 3 um from their origins.
    for wheel in WHEELS:
        assert link_state(api, wheel).pose.position.z == pytest.approx(AXLE_HEIGHT, abs=1e-6)

    def run(steps):
        """Steps in chunks of 10; the chassis' highest point and fastest speed seen, and the
        share of the samples with both wheels on the ground (axles within 2 mm of their radius
        up)."""
        highest, fastest, on_the_ground, samples = 0.0, 0.0, 0, 0
        for _ in range(steps // 10):
            assert api.step_simulation(10).success
            state = link_state(api, 'pioneer2dx::chassis')
            v = state.twist.linear
            highest = max(highest, state.pose.position.z)
            fastest = max(fastest, math.sqrt(v.x ** 2 + v.y ** 2 + v.z ** 2))
            samples += 1
            on_the_ground += all(abs(link_state(api, wheel).pose.position.z - AXLE_HEIGHT) < 0.002
                                 for wheel in WHEELS)
        return highest, fastest, on_the_ground / samples
    highest, fastest, grounded = run(1000)
    rested = model_pose(api, 'pioneer2dx')
    print('set at (3, 3, 0), 1 s at rest: at %s, chassis highest at %.4f m, fastest %.3f m/s, '
          'both wheels on the ground in %.0f %% of the samples'
          % (xyz(rested), highest, fastest, 100 * grounded))
    assert xyz(rested)[:2] == pytest.approx((3, 3), abs=0.05)
    assert highest < CHASSIS_HEIGHT + 0.03 and fastest < 1.5 and grounded >= 0.9

    # Its diff drive's odometry is the model frame's too (Gazebo's plugin reads the model's pose).
    odometry = []
    rospy_client.Subscriber('/odom', Odometry, odometry.append, queue_size=1000)
    command = rospy_client.Publisher('/cmd_vel', Twist, queue_size=1, latch=True)
    forward = Twist()
    forward.linear.x = 0.3
    command.publish(forward)

    def moving():
        assert api.step_simulation(10).success
        v = link_state(api, 'pioneer2dx::chassis').twist.linear
        return math.hypot(v.x, v.y) > 0.2
    wait_until(moving, 120, what='the pioneer to drive on cmd_vel')
    start = model_pose(api, 'pioneer2dx')
    highest, fastest, grounded = run(2000)
    driven = model_pose(api, 'pioneer2dx')
    dx, dy = driven.position.x - start.position.x, driven.position.y - start.position.y
    along = dx * math.cos(heading) + dy * math.sin(heading)
    across = -dx * math.sin(heading) + dy * math.cos(heading)
    print('driven 2 s at 0.3 m/s: %.4f m along its heading, %.4f m across, chassis highest at '
          '%.4f m, both wheels on the ground in %.0f %% of the samples'
          % (along, across, highest, 100 * grounded))
    assert along == pytest.approx(0.6, abs=0.06) and abs(across) < 0.3
    assert driven.position.z == pytest.approx(0, abs=0.02)
    assert highest < CHASSIS_HEIGHT + 0.03 and fastest < 1.5 and grounded >= 0.75
    wait_until(lambda: odometry, 60, what='odometry on /odom')
    assert odometry[-1].pose.pose.position.z == pytest.approx(0, abs=0.02)


def test_spawn_model_takes_an_sdfs_own_pose_in_its_pose(api, ros, tmp_path):
    """The issue's wall, spawned with spawn_model -sdf: without -x it sits at its own <pose>;
    with -x 1, and turned with -Y, its own pose is taken from there."""
    wall = tmp_path / 'wall.sdf'
    wall.write_text(wall_sdf('2.1 0 0.5 0 0 0'))

    def spawn(*args):
        result = ros.run(['rosrun', 'gazebo_ros', 'spawn_model', '-sdf', '-file', str(wall)]
                         + list(args))
        assert result.returncode == 0, result.stdout + result.stderr
    spawn('-model', 'wall')
    assert xyz(model_pose(api, 'wall')) == pytest.approx((2.1, 0, 0.5), abs=1e-12)
    assert xyz(link_state(api, 'wall::link').pose) == pytest.approx((2.1, 0, 0.5), abs=1e-12)
    spawn('-model', 'moved', '-x', '1')
    assert xyz(model_pose(api, 'moved')) == pytest.approx((3.1, 0, 0.5), abs=1e-12)
    spawn('-model', 'turned', '-x', '1', '-Y', str(math.pi / 2))
    got = model_pose(api, 'turned')
    assert xyz(got) == pytest.approx((1, 2.1, 0.5), abs=1e-12)
    assert yaw_of(got.orientation) == pytest.approx(math.pi / 2, abs=1e-12)
    # In another model's frame: that frame, the request, the model's own pose.
    spawn('-model', 'stacked', '-y', '1', '-reference_frame', 'wall')
    assert xyz(model_pose(api, 'stacked')) == pytest.approx((4.2, 1, 1), abs=1e-12)
    # reset_world puts it back where it was spawned, its own pose included.
    set_model_state(api, 'turned', pose(z=3.0), '')
    api.reset_world()
    assert xyz(model_pose(api, 'turned')) == pytest.approx((1, 2.1, 0.5), abs=1e-12)


def test_upstream_set_model_state_test_scenario(api, rospy_client):
    """gazebo_plugins' set_model_state_test on its world's pioneer2dx: ModelStates published on
    /gazebo/set_model_state in the frame pioneer2dx::chassis turn it to about 45 degrees (a turn
    of 0.08 rad each), then move it 0.1 m forward each until it is 5 m from the origin, x and y
    each within 0.2 m of sqrt(25 / 2); published in the world at (0, 0), it goes there, within
    0.01 m. Upstream publishes every 0.2 s of wall time on a world running at real time; here the
    world steps 0.2 s of sim time after each publish has taken effect. (Each set in the chassis'
    frame puts the model frame where the chassis was, 0.16 m up: the robot drops back onto its
    wheels, in Gazebo as here.)"""
    from gazebo_msgs.msg import ModelState
    spawn_pioneer(api)
    publisher = rospy_client.Publisher('/gazebo/set_model_state', ModelState, queue_size=5)
    wait_until(lambda: publisher.get_num_connections() > 0, 60,
               what='the simulator to subscribe to /gazebo/set_model_state')
    state = ModelState()
    state.model_name = 'pioneer2dx'
    state.pose.orientation.w = 1.0
    state.reference_frame = 'pioneer2dx::chassis'

    def publish_and_step(until, most=200):
        """Publishes `state` until `until(pose)` holds (upstream's do-while), each publish seen
        taking effect, then 0.2 s of sim time stepped; at most `most` publishes."""
        for _ in range(most):
            before = model_pose(api, 'pioneer2dx')
            publisher.publish(state)
            wait_until(lambda: model_pose(api, 'pioneer2dx') != before, 60,
                       what='the published state to take effect')
            assert api.step_simulation(200).success
            now = model_pose(api, 'pioneer2dx')
            if until(now):
                return now
        pytest.fail('%d publishes did not get there: %s' % (most, now))

    state.pose.orientation.z = 0.04018
    publish_and_step(lambda p: abs(yaw_of(p.orientation) - math.pi / 4) <= 0.05)
    state.pose.orientation.z = 0.0
    state.pose.position.x = 0.1
    there = publish_and_step(lambda p: math.hypot(p.position.x, p.position.y) >= 5.0)
    assert abs(there.position.x - 3.535533906) < 0.2 and abs(there.position.y - 3.535533906) < 0.2
    state.pose.position.x = 0.0
    state.reference_frame = 'world'
    back = publish_and_step(lambda p: math.hypot(p.position.x, p.position.y) <= 0.1)
    assert abs(back.position.x) < 0.01 and abs(back.position.y) < 0.01
