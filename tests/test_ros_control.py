"""ros_control inside the simulator, over real ROS on every engine: a URDF carrying
gazebo_ros_control's plugin tag gets controller_manager's services in its robotNamespace, the
book's controllers run inside the step loop, and bad configurations are refused with the
simulator alive.

The world is stepped with /gazebo/step_simulation, so every figure is sim time's alone.
"""
import os

import pytest
import yaml

from api_client import pose
from conftest import GROUND, start_sim
from controller_manager_cli import NS
from onedof_harness.private_ros import wait_until
from onedof_sim.tutorial import physics
# The book's controller configuration and the tutorial robot with its transmission and
# gazebo_ros_control tag (minimal_robot_w_jnt_ctl.launch loads both).
from test_book_jnt_ctl_files import BOOK_YAML, JNT_CTL_URDF

CM = NS + '/controller_manager/'
POSITION = 'joint1_position_controller'
STATES = 'joint_state_controller'
STEP_S = 0.001
LONGER_THAN_THE_TEST = 3600  # s: the suite's per-test timeout is 900


def book_params():
    """The YAML's parameters of the robot's namespace."""
    with open(BOOK_YAML) as f:
        return yaml.safe_load(f)[NS.strip('/')]


def controlled_urdf():
    with open(JNT_CTL_URDF) as f:
        return f.read()


class ControllerManager:
    """Proxies of <ns>/controller_manager/* with controller_manager_msgs' types."""

    def __init__(self, rospy):
        from controller_manager_msgs import srv
        self.rospy = rospy
        types = {'load_controller': srv.LoadController, 'unload_controller': srv.UnloadController,
                 'switch_controller': srv.SwitchController, 'list_controllers': srv.ListControllers,
                 'list_controller_types': srv.ListControllerTypes,
                 'reload_controller_libraries': srv.ReloadControllerLibraries}
        for name, service_type in types.items():
            rospy.wait_for_service(CM + name, timeout=60)
            setattr(self, name, rospy.ServiceProxy(CM + name, service_type))
        self.srv = srv

    def start(self, *names):
        return self.switch_controller(list(names), [], self.srv.SwitchControllerRequest.STRICT,
                                      False, 0.0).ok

    def stop(self, *names):
        return self.switch_controller([], list(names), self.srv.SwitchControllerRequest.STRICT,
                                      False, 0.0).ok

    def states(self):
        return {c.name: c for c in self.list_controllers().controller}


class Topics:
    """The robot's joint_states and the position controller's state, as they arrive."""

    def __init__(self, rospy):
        from control_msgs.msg import JointControllerState
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64
        self.joint_states, self.states = [], []
        self.subscribers = [
            rospy.Subscriber(NS + '/joint_states', JointState, self.joint_states.append),
            rospy.Subscriber(NS + '/%s/state' % POSITION, JointControllerState, self.states.append)]
        self.command_pub = rospy.Publisher(NS + '/%s/command' % POSITION, Float64, queue_size=1,
                                           latch=True)

    def wait_for_joint_states(self):
        """Until the simulator's joint_states publisher (made at load) is connected to us."""
        wait_until(lambda: self.subscribers[0].get_num_connections() > 0, 30,
                   what='the connection to joint_states')


@pytest.fixture
def robot(shared_sim, ros, rospy_client):
    """The tutorial robot with gazebo_ros_control's tag, the book's YAML loaded, paused at 0."""
    ros.master().setParam('/test', NS, book_params())
    res = shared_sim.spawn_urdf_model('one_DOF_robot', controlled_urdf(), '', pose(), '')
    assert res.success, res.status_message
    return shared_sim, ControllerManager(rospy_client), Topics(rospy_client)


# Bounds only a failure: at load 30 a step_simulation of 10 steps and the state that follows can
# take seconds, and the controller's realtime publisher drops a state its thread has not sent yet.
COMMAND_TAKEN_S = 300


def command(api, topics, value):
    """Publishes a command and steps until the controller's state shows it as its set point. The
    command goes out again with each try: a set point sent twice is the same set point, and the
    test does not hang on one message."""
    def taken():
        topics.command_pub.publish(value)
        api.step_simulation(10)
        return topics.states and topics.states[-1].set_point == value
    wait_until(taken, COMMAND_TAKEN_S, what='the controller to take command %g' % value)


def test_book_controllers_hold_the_commanded_angle(robot, engine):
    api, cm, topics = robot
    assert cm.load_controller(STATES).ok
    assert cm.load_controller(POSITION).ok
    states = cm.states()
    assert {n: s.state for n, s in states.items()} == {STATES: 'initialized', POSITION: 'initialized'}
    assert cm.start(STATES, POSITION)
    states = cm.states()
    assert {n: (s.state, s.type) for n, s in states.items()} == {
        STATES: ('running', 'joint_state_controller/JointStateController'),
        POSITION: ('running', 'effort_controllers/JointPositionController')}
    claimed = states[POSITION].claimed_resources
    assert [(c.hardware_interface, c.resources) for c in claimed] == [
        ('hardware_interface::EffortJointInterface', ['joint1'])]

    for target in (1.0, 2.0):
        command(api, topics, target)
        api.step_simulation(30000)
        position, rate = api.joint()
        assert position == pytest.approx(target, abs=1e-3)
        assert abs(rate) < 1e-3


def test_state_topic_reports_set_point_process_value_and_error(robot, engine):
    api, cm, topics = robot
    assert cm.load_controller(POSITION).ok and cm.start(POSITION)
    command(api, topics, 1.0)
    api.step_simulation(500)
    wait_until(lambda: topics.states and
               topics.states[-1].header.stamp.to_nsec() >= api.sim_time_ns() - 10 * 10 ** 6,
               30, what='the state at the paused time')
    state = topics.states[-1]
    position, rate = api.joint()
    assert state.set_point == 1.0
    # Published at the update of the step that then ran (at most 10 steps before the pause).
    assert state.process_value == pytest.approx(position, abs=0.05)
    assert state.error == pytest.approx(state.set_point - state.process_value, abs=1e-12)
    assert state.time_step == pytest.approx(STEP_S, abs=1e-12)
    assert (state.p, state.i, state.d, state.i_clamp) == (10.0, 10.0, 10.0, 10.0)
    # On every tenth update, as ros_controllers publish it (its queue of 1 may drop some while
    # step_simulation runs as fast as it can).
    stamps = [s.header.stamp.to_nsec() for s in topics.states]
    assert {(b - a) % (10 * 10 ** 6) for a, b in zip(stamps, stamps[1:])} == {0}


def test_joint_states_at_50_hz_of_sim_time(robot, engine):
    api, cm, topics = robot
    assert cm.load_controller(STATES).ok and cm.start(STATES)
    topics.wait_for_joint_states()
    api.step_simulation(100)
    start_ns = api.sim_time_ns()
    end_ns = start_ns + 10 ** 9
    # 20 ms of sim time at a time, each one's message received before the next: its publisher's
    # queue (4, as joint_state_controller's) never overflows, however busy the machine.
    while api.sim_time_ns() < end_ns + 40 * 10 ** 6:
        reached_ns = api.step_simulation(20).sim_time.to_nsec()
        wait_until(lambda: topics.joint_states and
                   topics.joint_states[-1].header.stamp.to_nsec() > reached_ns - 20 * 10 ** 6,
                   30, what='joint_states of the last 20 ms')
    stamps = [m.header.stamp.to_nsec() for m in topics.joint_states]
    assert len([s for s in stamps if start_ns <= s < end_ns]) == 50
    last = topics.joint_states[-1]
    assert list(last.name) == ['joint1'] and len(last.position) == len(last.velocity) == 1


def test_without_integral_the_link_settles_at_the_pd_static_balance(robot, engine, ros):
    api, cm, topics = robot
    ros.master().setParam('/test', NS + '/%s/pid/i' % POSITION, 0.0)
    assert cm.load_controller(POSITION).ok and cm.start(POSITION)
    command(api, topics, 1.0)
    api.step_simulation(30000)
    assert api.joint()[0] == pytest.approx(physics.settled_angle(1.0, kp=10.0), abs=1e-3)


def test_switching_off_stops_the_torque_at_the_next_step(robot, engine):
    api, cm, topics = robot
    assert cm.load_controller(POSITION).ok and cm.start(POSITION)
    command(api, topics, 1.0)
    api.step_simulation(30000)
    position, rate = api.joint()
    assert abs(rate) < 1e-3
    assert cm.stop(POSITION)
    assert cm.states()[POSITION].state == 'stopped'
    api.step_simulation(1)
    # Gravity alone acts in that step: the holding torque is gone.
    expected = physics.gravity_torque(position) / physics.INERTIA_ABOUT_JOINT * STEP_S
    assert api.joint()[1] - rate == pytest.approx(expected, rel=0.05)


@pytest.mark.parametrize('change, reason', [
    ({'type': 'effort_controllers/NoSuchController'}, "controller type 'effort_controllers/NoSuchController' does not exist"),
    ({'joint': None}, 'No joint given'),
    ({'joint': 'joint7'}, "Could not find resource 'joint7'"),
    ({'joint': 'glue_robot_to_world'}, "Could not find resource 'glue_robot_to_world'"),
    ({'pid': None}, 'No p gain specified for pid'),
    ({'type': None}, 'the type was not specified'),
    ({'type': 'position_controllers/JointPositionController'}, 'effort only'),
])
def test_bad_configuration_refused_with_the_simulator_alive(robot, engine, ros, change, reason):
    api, cm, topics = robot
    name = POSITION
    for key, value in change.items():
        param = NS + '/%s/%s' % (name, key)
        if value is None:
            ros.master().deleteParam('/test', param)
        else:
            ros.master().setParam('/test', param, value)
    logged_before = ros.log_text('sim_' + engine).count(reason)
    assert not cm.load_controller(name).ok
    assert cm.states() == {}
    wait_until(lambda: ros.log_text('sim_' + engine).count(reason) > logged_before, 30,
               what='the simulator to log %r' % reason)
    # The world goes on, intact.
    assert api.step_simulation(10).success
    assert api.get_world_properties().model_names == [GROUND, 'one_DOF_robot']
    assert cm.load_controller(STATES).ok


def test_controller_manager_services_as_ros_control_answers(robot, engine, rospy_client):
    api, cm, topics = robot
    types = cm.list_controller_types()
    assert 'effort_controllers/JointPositionController' in types.types
    assert set(types.base_classes) == {'controller_interface::ControllerBase'}
    assert cm.load_controller(POSITION).ok
    assert not cm.load_controller(POSITION).ok  # already loaded
    assert cm.start(POSITION)
    assert not cm.start(POSITION)  # STRICT: already running
    best_effort = cm.srv.SwitchControllerRequest.BEST_EFFORT
    assert cm.switch_controller([POSITION, 'nope'], [], best_effort, False, 0.0).ok
    assert not cm.unload_controller(POSITION).ok  # still running
    # A second controller on joint1 loads, but may not run beside the first.
    second = 'second_position_controller'
    rospy_client.set_param(NS + '/' + second, book_params()[POSITION])
    assert cm.load_controller(second).ok
    assert not cm.start(second)
    assert not cm.switch_controller([second], [], best_effort, False, 0.0).ok
    assert cm.switch_controller([second], [POSITION], best_effort, False, 0.0).ok  # a handover
    assert {n: s.state for n, s in cm.states().items()} == {POSITION: 'stopped',
                                                             second: 'running'}
    assert not cm.reload_controller_libraries(False).ok
    assert cm.reload_controller_libraries(True).ok
    assert cm.states() == {}
    assert cm.load_controller(POSITION).ok and cm.unload_controller(POSITION).ok
    # Deleting the model takes its controller_manager away.
    assert api.delete_model('one_DOF_robot').success
    import rosservice
    wait_until(lambda: CM + 'list_controllers' not in rosservice.get_service_list(), 30,
               what='the controller_manager services to go')


def test_lockstep_world_with_in_sim_controllers_advances(ros, engine, rospy_client):
    """The in-simulator controllers act inside the step: lock-step has no controller to wait for.
    Its timeout is longer than this test may run, so a world that waited for one would stand
    still: that it advances is the proof."""
    from api_client import GazeboApi
    start_sim(ros, engine, ['_lockstep:=true', '_lockstep_timeout:=%d' % LONGER_THAN_THE_TEST])
    ros.master().setParam('/test', NS, book_params())
    api = GazeboApi(rospy_client)
    res = api.spawn_urdf_model('one_DOF_robot', controlled_urdf(), '', pose(), '')
    assert res.success, res.status_message
    cm = ControllerManager(rospy_client)
    assert cm.load_controller(POSITION).ok and cm.start(POSITION)
    start_ns = api.sim_time_ns()
    wait_until(lambda: api.sim_time_ns() > start_ns + 10 ** 9, 300, what='the world to run')


def test_reset_world_restarts_the_controllers_holding_where_the_link_is(robot, engine):
    api, cm, topics = robot
    assert cm.load_controller(POSITION).ok and cm.start(POSITION)
    command(api, topics, 1.0)
    api.step_simulation(30000)
    assert api.joint()[0] == pytest.approx(1.0, abs=1e-3)
    # As gazebo_ros_control: the running controllers restart (starting(): the set point is the
    # position then, the integral 0), so the arm, reset upright, is held there.
    api.reset_world()
    api.step_simulation(5000)
    position, rate = api.joint()
    assert position == pytest.approx(0.0, abs=1e-3)
    wait_until(lambda: topics.states[-1].header.stamp.to_nsec() >= api.sim_time_ns() - 10 ** 7,
               30, what='the state after the reset')
    assert topics.states[-1].set_point == pytest.approx(0.0, abs=1e-9)


def test_second_robot_in_the_same_namespace_is_refused_the_first_keeps_its_manager(robot, engine,
                                                                                     ros):
    api, cm, topics = robot
    refusal = "model 'one_DOF_robot' already has the controller_manager in /one_DOF_robot"
    refused_before = ros.log_text('sim_' + engine).count(refusal)
    res = api.spawn_urdf_model('second_robot', controlled_urdf(), '', pose(x=2.0), '')
    assert res.success, res.status_message  # the model is spawned, as Gazebo would
    wait_until(lambda: ros.log_text('sim_' + engine).count(refusal) > refused_before, 30,
               what='the refusal in the log')
    assert cm.load_controller(POSITION).ok and cm.start(POSITION)
    assert api.delete_model('second_robot').success
    assert cm.states()[POSITION].state == 'running'
