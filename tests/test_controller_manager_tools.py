"""`rosrun controller_manager spawner|controller_manager ...` end to end against the simulator's own
controller manager (the book's robot with gazebo_ros_control's tag, the book's parameters), in the
book's namespace: the tools' command lines, service names and exit statuses. The tools do not
depend on the engine, so they run against the first one's simulator only."""

import os
import signal

import pytest

from api_client import pose
from conftest import ENGINES
from controller_manager_cli import (BOOK_CONTROLLERS_RUNNING, NS, STATE_CONTROLLER_RUNNING, cli,
                                     listing, wait_for_listing)
from test_ros_control import book_params, controlled_urdf

ONE_ENGINE = pytest.mark.parametrize('engine', ENGINES[:1], indirect=True)


@pytest.fixture
def manager(shared_sim, ros):
    """The module's simulator with the book's robot spawned and its parameters loaded."""
    ros.set_param(NS, book_params())
    res = shared_sim.spawn_urdf_model('one_DOF_robot', controlled_urdf(), '', pose(), '')
    assert res.success, res.status_message
    ros.wait_for_service(NS + '/controller_manager/switch_controller')
    return ros


@ONE_ENGINE
def test_spawner_loads_and_starts_then_takes_down_on_sigint(manager, rospy_client):
    ros = manager
    spawner = ros.start(['rosrun', 'controller_manager', 'spawner', 'joint_state_controller',
                         'joint1_position_controller', '__ns:=' + NS], name='spawner',
                        may_exit=True)
    wait_for_listing(ros, rospy_client, BOOK_CONTROLLERS_RUNNING, 'both controllers running')
    os.killpg(spawner.pid, signal.SIGINT)
    assert spawner.wait(timeout=300) == 0, ros.log_text(spawner)
    assert listing(ros) == ['No controllers are loaded in mechanism control']


@ONE_ENGINE
def test_spawner_stopped_and_namespace_option(manager, rospy_client):
    ros = manager
    spawner = ros.start(['rosrun', 'controller_manager', 'spawner', '--stopped', '--namespace',
                         NS, 'joint_state_controller'], name='spawner', may_exit=True)
    loaded = ['joint_state_controller - hardware_interface::JointStateInterface ( initialized )']
    wait_for_listing(ros, rospy_client, loaded, 'controller loaded, not started')
    ros.terminate(spawner)
    assert listing(ros) == ['No controllers are loaded in mechanism control']


@ONE_ENGINE
def test_spawner_exits_nonzero_naming_the_controller_that_would_not_load(manager):
    ros = manager
    out = ros.run(['rosrun', 'controller_manager', 'spawner', 'joint_state_controller',
                   'no_such_controller', '__ns:=' + NS])
    assert out.returncode == 1
    assert "Failed to load controller 'no_such_controller'" in out.stdout + out.stderr
    # What it had loaded before the failure is unloaded again.
    assert listing(ros) == ['No controllers are loaded in mechanism control']


def test_spawner_without_a_controller_manager_gives_up_after_its_timeout(ros):
    out = ros.run(['rosrun', 'controller_manager', 'spawner', '--timeout', '1', 'x',
                   '__ns:=' + NS])
    assert out.returncode == 1
    assert "couldn't find the expected controller_manager" in out.stdout + out.stderr


@ONE_ENGINE
def test_spawner_waits_for_true_on_its_wait_for_topic(manager, rospy_client):
    ros = manager
    ros.start(['rosrun', 'controller_manager', 'spawner', '--wait-for', '/ready',
               'joint_state_controller', '__ns:=' + NS], name='spawner', may_exit=True)

    def subscribed():
        code, _, state = ros.master().getSystemState('/test')
        return any(topic == '/ready' for topic, _ in state[1])
    ros.wait_until(subscribed, 60, what='the spawner to subscribe to /ready')
    assert listing(ros) == ['No controllers are loaded in mechanism control']
    ros.start(['rostopic', 'pub', '-l', '/ready', 'std_msgs/Bool', 'true'], name='ready')
    wait_for_listing(ros, rospy_client, [STATE_CONTROLLER_RUNNING],
                     'the controller running after True on /ready')


def test_spawner_interrupted_while_waiting_for_services_ends_at_once(ros):
    # Told to wait an hour for the services: ending well before that, it ended on Ctrl-C.
    spawner = ros.start(['rosrun', 'controller_manager', 'spawner', '--timeout', '3600',
                         'joint_state_controller', '__ns:=' + NS], name='spawner', may_exit=True)

    def waiting():
        return 'Waiting for service' in ros.log_text(spawner)
    ros.wait_until(waiting, 60, what='the spawner to wait for the controller manager')
    os.killpg(spawner.pid, signal.SIGINT)
    assert spawner.wait(timeout=600) == 0, ros.log_text(spawner)


@ONE_ENGINE
def test_controller_manager_commands(manager):
    ros = manager
    assert cli(ros, 'spawn', 'joint_state_controller').stdout.splitlines() == [
        'Loaded joint_state_controller', "Started ['joint_state_controller'] successfully"]
    out = cli(ros, 'load', 'joint1_position_controller')
    assert (out.returncode, out.stdout.strip()) == (0, 'Loaded joint1_position_controller')
    assert listing(ros) == [
        'joint_state_controller - hardware_interface::JointStateInterface ( running )',
        'joint1_position_controller - hardware_interface::EffortJointInterface ( initialized )']
    assert cli(ros, 'start', 'joint1_position_controller').returncode == 0
    assert cli(ros, 'stop', 'joint1_position_controller').returncode == 0
    assert cli(ros, 'unload', 'joint1_position_controller').stdout.strip() == (
        'Unloaded joint1_position_controller successfully')
    assert cli(ros, 'kill', 'joint_state_controller').returncode == 0
    assert listing(ros) == ['No controllers are loaded in mechanism control']
    out = cli(ros, 'load', 'no_such_controller')
    assert (out.returncode, out.stdout.strip()) == (1, 'Error when loading no_such_controller')
    assert sorted(cli(ros, 'list-types').stdout.splitlines()) == [
        'effort_controllers/JointEffortController',
        'effort_controllers/JointPositionController',
        'effort_controllers/JointVelocityController',
        'joint_state_controller/JointStateController',
        'position_controllers/JointPositionController']
    out = cli(ros, 'frobnicate')
    assert out.returncode == 1 and 'spawn <name>' in out.stdout
