"""End-to-end tests of minimal_joint_controller driving the simulator over a real roscore.

The simulator runs in lock-step with the controller at the tutorial's real-time factor 1: it waits
for the controller's command at the end of every period, so a busy machine (two tests side by side
on two cores) slows the run down but never leaves the link without torque. The figures are the
physics' alone: the rest angles are those of the closed form to the engines' accuracy, and every
period of sim time has its sample.

Sign conventions (checked here against the running simulator): q > 0 tilts link2 toward +x, gravity
pulls it further (+m g d sin q about +y), so at rest the controller holds jnt_trq = -m g d sin q
and Kp (c - q) + m g d sin q = 0 puts the link beyond the command c for 0 < c < pi.
"""
import collections
import math
import os
import signal

import pytest

from api_client import ROBOT, GazeboApi
from conftest import ENGINES, GROUND, TUTORIAL_URDF, start_sim
from onedof_harness.private_ros import wait_until
from onedof_sim.transforms import quaternion_multiply
from onedof_sim.tutorial import physics

CONTROLLER = ['rosrun', 'minimal_joint_controller', 'minimal_joint_controller']
RATE_HZ = 100.0
LOCKSTEP = ['_lockstep:=true']  # at the default max_update_rate: real-time factor 1 at most
# How far the rest angle may be from the closed form: the engines' joint error (core_test) and the
# 0.5 s tail mean of a link still settling by less than that.
REST_TOLERANCE = 2e-4
# How steady jnt_trq is once settled: Kp times a tenth of a mrad, well within the 1e-3 relative
# tolerance of the holding torque (about 4 N m at command 1).
TORQUE_BAND = 1e-3
# How long after its first sample a controller is surely lock-stepped (its first effort is applied
# a period after the sample; the world ran free until then).
LOCKSTEP_ENGAGED = 0.2
# What the controller does with its topics, commands and a lost or reset simulator does not depend
# on the engine: those tests run against the first one only; the physics runs on every engine.
ONE_ENGINE = pytest.mark.parametrize('engine', ENGINES[:1], indirect=True)


def start_controller(ros, args=()):
    return ros.start(CONTROLLER + list(args), name='controller')


class Topic:
    """Every message of a topic with the ROS time (sim time) at which it arrived."""

    def __init__(self, rospy, name, msg_class):
        self.rospy = rospy
        self.samples = []
        rospy.Subscriber(name, msg_class, self._on_message, queue_size=1000)

    def _on_message(self, msg):
        self.samples.append((self.rospy.get_time(), msg))

    def clear(self):
        self.samples = []

    def since(self, start):
        return [(t, msg) for t, msg in list(self.samples) if t >= start]

    def values_since(self, start):
        return [(t, msg.data) for t, msg in self.since(start)]

    def steady_tail(self, start, window, band, after=0.0):
        """The (t, value) samples of the last `window` s of sim time, if they stay within `band`
        and at least window + after s have passed since `start`; else None."""
        samples = self.values_since(start)
        if not samples or samples[-1][0] - start < window + after:
            return None
        tail = [(t, v) for t, v in samples if t >= samples[-1][0] - window]
        values = [v for _, v in tail]
        return tail if max(values) - min(values) <= band else None


class ControlledRobot:
    """The tutorial's setup: simulator, controller running, robot spawned, a pos_cmd publisher and
    listeners on the controller's topics.

    The controller starts before the robot is spawned, so the upright link (an unstable balance)
    is held from the first period instead of depending on how long an engine keeps it balanced
    on its own."""

    def __init__(self, ros, engine, rospy, spawn=True, sim_args=LOCKSTEP, controller_args=()):
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64
        self.ros, self.engine, self.rospy = ros, engine, rospy
        self.Float64 = Float64
        self.sim = start_sim(ros, engine, sim_args)
        self.jnt_pos = Topic(rospy, '/jnt_pos', Float64)
        self.jnt_vel = Topic(rospy, '/jnt_vel', Float64)
        self.jnt_trq = Topic(rospy, '/jnt_trq', Float64)
        self.joint_states = Topic(rospy, '/joint_states', JointState)
        self.pos_cmd = rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
        self.controller = start_controller(ros, controller_args)
        wait_until(lambda: self.controller.poll() is not None
                   or self.pos_cmd.get_num_connections() > 0, 60,
                   what='the controller to subscribe to pos_cmd')
        self.assert_controller_alive()
        if spawn:
            self.spawn()

    def missing_joint_warnings(self):
        return self.controller_log().count('cannot read joint joint1')

    def spawn(self, warnings_before=0):
        """Spawns the robot once the controller has warned about the missing joint1 (more than
        `warnings_before` times)."""
        wait_until(lambda: self.missing_joint_warnings() > warnings_before, 60,
                   what='the controller to look for joint1')
        GazeboApi(self.rospy).spawn_robot()

    def assert_controller_alive(self):
        assert self.controller.poll() is None, \
            'controller exited:\n' + self.ros.log_text(self.controller)

    def controller_log(self):
        return self.ros.log_text(self.controller)

    def now(self):
        return self.rospy.get_time()

    def command(self, value):
        """Publishes pos_cmd; returns the sim time just before."""
        start = self.now()
        self.pos_cmd.publish(self.Float64(value))
        return start

    def wait_sim_time(self, duration):
        end = self.now() + duration
        wait_until(lambda: self.now() >= end, duration * 20 + 30,
                   what='%.1f s of sim time' % duration)

    def wait_settled(self, since, window=1.0, band=0.001, torque_band=TORQUE_BAND, timeout=120):
        """Waits until jnt_pos has stayed within `band` rad and jnt_trq within `torque_band` N m
        for `window` s of sim time; returns the mean position and mean jnt_trq over that window.

        Both are asked to be steady because they are separate topics, each sample stamped with
        its arrival: on a busy machine a torque of the approach can arrive inside the position's
        window, and a steady position alone would let it into the mean."""
        def settled():
            self.assert_controller_alive()
            tail = self.jnt_pos.steady_tail(since, window, band)
            if not tail or len(tail) < window * RATE_HZ * 0.5:
                return None
            torque_tail = self.jnt_trq.steady_tail(since, window, torque_band)
            if not torque_tail or len(torque_tail) < window * RATE_HZ * 0.5:
                return None
            positions = [q for _, q in tail]
            torques = [u for _, u in torque_tail]
            return sum(positions) / len(positions), sum(torques) / len(torques)
        return wait_until(settled, timeout, interval=0.2,
                          what='jnt_pos to settle within %g rad and jnt_trq within %g N m for %g s'
                          % (band, torque_band, window))


@pytest.fixture
def sim_time_client(ros, request):
    """rospy on sim time: /use_sim_time set before it starts, so its clock is the simulator's."""
    ros.set_param('/use_sim_time', True)
    return request.getfixturevalue('rospy_client')


@pytest.fixture
def robot(ros, engine, sim_time_client):
    return ControlledRobot(ros, engine, sim_time_client)


def assert_holds_at(settled, command):
    q, torque = settled
    expected = physics.settled_angle(command)
    assert expected > command
    assert q == pytest.approx(expected, abs=REST_TOLERANCE), \
        'settled at %.4f rad, Kp (c - q) + m g d sin q = 0 gives %.4f' % (q, expected)
    # At rest the controller's torque cancels gravity's +m g d sin q.
    assert torque == pytest.approx(-physics.gravity_torque(q), rel=1e-3), \
        'holding %.4f N m at q = %.4f, gravity needs %.4f' % (torque, q, -physics.gravity_torque(q))


def test_commands_1_then_2_settle_beyond_the_command_against_gravity(robot):
    robot.wait_settled(since=robot.now())  # upright at command 0 first
    assert_holds_at(robot.wait_settled(since=robot.command(1.0)), 1.0)

    start = robot.command(2.0)
    settled = robot.wait_settled(since=start)
    assert_holds_at(settled, 2.0)
    peak = max(q for _, q in robot.jnt_pos.values_since(start))
    assert peak > settled[0] + 0.01, 'the step to 2.0 does not overshoot: peak %.4f, settled %.4f' \
        % (peak, settled[0])


# The engines at the tutorial's rate; 1 kHz (a period of one step: every step a lock-step stop)
# on one, as the rate is the controller's and the lock-step's: the engines step the same 1 ms
# steps at either rate.
@pytest.mark.parametrize('engine, rate', [(engine, RATE_HZ) for engine in ENGINES]
                         + [(ENGINES[0], 1000.0)], indirect=['engine'])
def test_every_period_is_sampled_at_100_hz_and_1_khz(ros, engine, sim_time_client, rate):
    robot = ControlledRobot(ros, engine, sim_time_client, controller_args=['_rate:=%g' % rate])
    robot.command(1.0)
    # From the first sample it hears on, this process hears every one (a connection delivers in
    # order, and the queues hold a second of them). The window starts once the samples span
    # LOCKSTEP_ENGAGED of sim time: the world runs free until the controller's first effort.
    def lead_in_end_ns():
        samples = [msg.header.stamp.to_nsec() for _, msg in list(robot.joint_states.samples)]
        if samples and samples[-1] - samples[0] >= LOCKSTEP_ENGAGED * 1e9:
            return samples[-1]
        return None
    start_ns = wait_until(lead_in_end_ns, 120, what='%g s of joint_states' % LOCKSTEP_ENGAGED)
    end_ns = start_ns + round(2.0 * 1e9)

    # joint_states by their stamps alone, the sim time at which the controller read the joint
    # (not by when they arrived: this process's clock and the samples come on two connections):
    # one per period, each a period after the one before, none missed.
    def stamps():
        return [msg.header.stamp.to_nsec() for _, msg in list(robot.joint_states.samples)]
    wait_until(lambda: any(t >= end_ns for t in stamps()), 120,
               what='joint_states stamped past the window')
    period_ns = round(1e9 / rate)
    stamps = [t for t in stamps() if start_ns <= t < end_ns]
    gaps = {b - a for a, b in zip(stamps, stamps[1:])}
    assert gaps == {period_ns}, 'sample spacings (ns): %s' % sorted(gaps)
    assert len(stamps) == round(2.0 * rate)
    # Each sample goes out on the Float64 topics too: between two pauses, each of them has had
    # as many messages as joint_states (counted from the pause on, as the four connections may
    # have come up a few messages apart).
    api = GazeboApi(robot.rospy)
    counts = [caught_up_counts(robot, api)]
    api.unpause_physics()
    robot.wait_sim_time(0.5)
    counts.append(caught_up_counts(robot, api))
    assert len({after - before for before, after in zip(*counts)}) == 1, counts


def caught_up_counts(robot, api):
    """Pauses the world; once each Float64 topic has delivered the last joint_states sample's
    value, returns how many messages each of joint_states, jnt_pos, jnt_vel, jnt_trq brought."""
    api.pause_physics()

    def caught_up():
        if not robot.joint_states.samples:
            return False
        last = robot.joint_states.samples[-1][1]
        fields = ((robot.jnt_pos, last.position[0]), (robot.jnt_vel, last.velocity[0]),
                  (robot.jnt_trq, last.effort[0]))
        return all(topic.samples and topic.samples[-1][1].data == value
                   for topic, value in fields)
    wait_until(caught_up, 30, what='jnt_pos, jnt_vel and jnt_trq to bring the last sample')
    return [len(topic.samples) for topic in (robot.joint_states, robot.jnt_pos, robot.jnt_vel,
                                             robot.jnt_trq)]


@ONE_ENGINE
def test_joint_states_carry_the_joint_and_match_jnt_pos(robot):
    robot.command(1.0)
    robot.wait_sim_time(1.0)
    _, state = robot.joint_states.samples[-1]
    assert state.name == ['joint1']
    assert len(state.position) == len(state.velocity) == 1
    # The same reading goes out on both topics (the last few may still be on their way).
    positions = {msg.data for _, msg in robot.jnt_pos.samples}
    recent = [msg for _, msg in robot.joint_states.samples[-50:]]
    assert sum(msg.position[0] in positions for msg in recent) >= len(recent) - 2


@ONE_ENGINE
def test_joint_states_drive_robot_state_publisher(ros, robot):
    from tf2_msgs.msg import TFMessage
    rospy = robot.rospy
    with open(TUTORIAL_URDF) as f:
        ros.set_param('/robot_description', f.read())
    ros.start(['rosrun', 'robot_state_publisher', 'robot_state_publisher'],
              name='robot_state_publisher')
    moving, static = {}, {}

    def on_tf(msg, frames):
        for t in msg.transforms:
            if (t.header.frame_id, t.child_frame_id) in (('link1', 'link2'), ('world', 'link1')):
                frames.setdefault(t.child_frame_id, {})[t.header.stamp.to_sec()] = t.transform

    rospy.Subscriber('/tf', TFMessage, on_tf, callback_args=moving, queue_size=1000)
    rospy.Subscriber('/tf_static', TFMessage, on_tf, callback_args=static, queue_size=10)
    robot.command(1.0)

    def matched():
        """(q, link1 -> link2 transform) of the joint_states and transforms with one stamp. A
        controller running late can stamp two readings with one sim time: those are left out."""
        samples = list(robot.joint_states.samples)
        stamp_counts = collections.Counter(msg.header.stamp.to_sec() for _, msg in samples)
        states = {msg.header.stamp.to_sec(): msg.position[0] for _, msg in samples
                  if stamp_counts[msg.header.stamp.to_sec()] == 1}
        return [(states[stamp], transform) for stamp, transform in
                list(moving.get('link2', {}).items()) if stamp in states]

    wait_until(lambda: 'link1' in static and len(matched()) > 100
               and max(q for q, _ in matched()) > 1.0, 120,
               what='robot_state_publisher transforms of link1 (static) and of link2 past 1 rad')
    world_link1 = next(iter(static['link1'].values()))
    for q, link1_link2 in matched():
        r1, r2 = world_link1.rotation, link1_link2.rotation
        x, y, z, w = quaternion_multiply((r1.x, r1.y, r1.z, r1.w), (r2.x, r2.y, r2.z, r2.w))
        # link2 in world: rotation by q about +y, quaternion (0, sin q/2, 0, cos q/2) up to sign.
        dot = y * math.sin(q / 2) + w * math.cos(q / 2)
        assert abs(abs(dot) - 1) < 1e-6 and abs(x) < 1e-9 and abs(z) < 1e-9, (q, (x, y, z, w))
        t = link1_link2.translation
        assert (t.x, t.y, t.z) == pytest.approx((0, 0, 1), abs=1e-9)


@ONE_ENGINE
def test_controller_survives_a_killed_simulator_and_resumes_after_restart(ros, engine, robot):
    assert_holds_at(robot.wait_settled(since=robot.command(1.0)), 1.0)
    os.killpg(robot.sim.pid, signal.SIGKILL)
    robot.sim.wait(timeout=10)
    robot.assert_controller_alive()

    # Sim time stands still without a simulator, so the controller (sleeping in sim time) finds
    # out when the new one's clock starts from 0 and its old connections fail.
    warnings_before = robot.missing_joint_warnings()
    robot.sim = start_sim(ros, engine, LOCKSTEP)
    wait_until(lambda: 'lost the simulator' in robot.controller_log(), 60,
               what='the controller to notice the simulator was replaced')
    for topic in (robot.jnt_pos, robot.jnt_vel, robot.jnt_trq, robot.joint_states):
        topic.clear()
    wait_until(lambda: robot.missing_joint_warnings() > warnings_before, 60,
               what='the controller to reconnect and find no joint1 in the new world')
    assert not robot.jnt_pos.samples, 'jnt_pos published without a joint to read'

    robot.spawn(warnings_before)
    wait_until(lambda: robot.jnt_pos.samples, 60, what='jnt_pos after the restart')
    assert_holds_at(robot.wait_settled(since=robot.jnt_pos.samples[0][0]), 1.0)
    robot.assert_controller_alive()
    log = robot.controller_log()
    assert log.count('lost the simulator') == 1, log


@ONE_ENGINE
def test_controller_goes_on_across_a_restarted_roscore(ros, robot):
    """A roscore restarted on the same port under the running simulator and controller: the
    controller's connections to the simulator are peer to peer and go on; the simulator registers
    its services, topics and parameters with the new master, so new clients find it."""
    assert_holds_at(robot.wait_settled(since=robot.command(1.0)), 1.0)
    ros.restart_master()

    ros.wait_until(lambda: ros.has_service('/gazebo/get_world_properties'), 60,
                   what='the simulator to register its services with the new master')
    ros.wait_until(lambda: ros.master().hasParam('/test', '/use_sim_time')[2], 60,
                   what='the simulator to set /use_sim_time on the new master')
    assert ros.master().getParam('/test', '/use_sim_time')[2] is True
    ros.wait_until(lambda: 'the ROS master came back' in ros.log_text(robot.sim), 60,
                   what='the simulator to say it registered again')
    # Through the new master, from this node (rospy looks the service up per call) and from new
    # ones: a service call, and the clock on a new subscriber.
    assert GazeboApi(robot.rospy).get_world_properties().model_names == [GROUND, ROBOT]
    called = ros.run(['rosservice', 'call', '/gazebo/get_world_properties'])
    assert called.returncode == 0 and ROBOT in called.stdout, called.stdout + called.stderr
    echoed = ros.run(['rostopic', 'echo', '-n', '1', '/clock'])
    assert echoed.returncode == 0 and 'secs:' in echoed.stdout, echoed.stdout + echoed.stderr

    # The controller goes on: a command sent after the restart is held where physics says.
    assert_holds_at(robot.wait_settled(since=robot.command(2.0)), 2.0)
    robot.assert_controller_alive()
    assert 'lost the simulator' not in robot.controller_log()


@ONE_ENGINE
def test_controller_keeps_control_across_reset_simulation(robot):
    assert_holds_at(robot.wait_settled(since=robot.command(1.0)), 1.0)
    before = robot.now()
    GazeboApi(robot.rospy).reset_simulation()
    wait_until(lambda: robot.now() < before, 30, what='sim time to jump back')
    for topic in (robot.jnt_pos, robot.jnt_trq):
        topic.clear()
    # Back upright at time 0, the controller carries on from the new time and settles again.
    wait_until(lambda: robot.jnt_pos.samples, 30, what='jnt_pos after the reset')
    assert robot.jnt_pos.samples[0][0] < before
    assert_holds_at(robot.wait_settled(since=robot.jnt_pos.samples[0][0]), 1.0)
    robot.assert_controller_alive()
    assert 'lost the simulator' not in robot.controller_log()


@ONE_ENGINE
def test_non_finite_command_is_ignored_with_a_warning(robot):
    assert_holds_at(robot.wait_settled(since=robot.command(1.0)), 1.0)
    start = robot.command(float('nan'))
    wait_until(lambda: 'ignoring pos_cmd nan' in robot.controller_log(), 30,
               what='the controller to warn about the NaN command')
    robot.command(float('inf'))
    wait_until(lambda: 'ignoring pos_cmd inf' in robot.controller_log(), 30,
               what='the controller to warn about the infinite command')
    robot.wait_sim_time(1.0)
    assert all(math.isfinite(u) for _, u in robot.jnt_trq.values_since(start))
    assert_holds_at(robot.wait_settled(since=start), 1.0)
    # Still controlling: a new finite command is followed.
    assert_holds_at(robot.wait_settled(since=robot.command(0.5)), 0.5)
    robot.assert_controller_alive()


@ONE_ENGINE
def test_controller_waits_for_the_joint_and_takes_it_once_spawned(ros, engine, sim_time_client):
    robot = ControlledRobot(ros, engine, sim_time_client, spawn=False)
    wait_until(robot.missing_joint_warnings, 60, what='the controller to warn that joint1 is missing')
    start = robot.now()
    robot.wait_sim_time(11.0)
    robot.assert_controller_alive()
    assert not robot.jnt_pos.samples and not robot.jnt_trq.samples \
        and not robot.joint_states.samples, 'published without a joint to read'
    # Throttled: one warning per 5 s of sim time, not one per period.
    assert robot.missing_joint_warnings() <= 4

    robot.command(1.0)
    robot.spawn()
    wait_until(lambda: robot.jnt_pos.since(start), 60, what='jnt_pos once the robot is spawned')
    assert_holds_at(robot.wait_settled(since=robot.now()), 1.0)


@ONE_ENGINE
def test_tutorial_plot_command_records_the_controller_in_sim_time(ros, robot, tmp_path):
    from onedof_sim.tools.plot import read_csv
    robot.command(2.0)
    png, csv_path = str(tmp_path / 'plot.png'), str(tmp_path / 'plot.csv')
    result = ros.run(['rosrun', 'onedof_sim', 'plot', '/jnt_pos/data', '/jnt_trq/data',
                      '/jnt_vel/data', '--duration', '3', '--png', png, '--csv', csv_path],
                     timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    assert os.path.getsize(png) > 5000
    series = read_csv(csv_path)
    assert list(series) == ['/jnt_pos/data', '/jnt_trq/data', '/jnt_vel/data']
    for label, topic in (('/jnt_pos/data', robot.jnt_pos), ('/jnt_trq/data', robot.jnt_trq)):
        times, values = series[label]
        # What the plotter recorded is a run of consecutive messages this test received too.
        received = [msg.data for _, msg in topic.samples]
        starts = [i for i, v in enumerate(received) if v == values[0]]
        assert any(received[i:i + len(values)] == values for i in starts), label
        # 3 s of sim time at 100 Hz, on a sim-time axis.
        assert 2.9 <= times[-1] - times[0] <= 3.1
        assert len(values) == pytest.approx(RATE_HZ * (times[-1] - times[0]), rel=0.1)
