"""`rosrun controller_manager spawner|controller_manager ...` end to end against a stand-in
controller manager (tests/fake_controller_manager.py) in the book's namespace: the tools' command
lines, service names and exit statuses. The simulator's own controller manager is tested with
the simulator."""

import os
import signal

import pytest

NS = '/one_DOF_robot'
FAKE = os.path.join(os.path.dirname(__file__), 'fake_controller_manager.py')
BOOK_PARAMS = {
    'joint_state_controller': {'type': 'joint_state_controller/JointStateController',
                               'publish_rate': 50},
    'joint1_position_controller': {'type': 'effort_controllers/JointPositionController',
                                   'joint': 'joint1',
                                   'pid': {'p': 10.0, 'i': 10.0, 'd': 10.0,
                                           'i_clamp_min': -10.0, 'i_clamp_max': 10.0}},
}


@pytest.fixture
def manager(ros):
    ros.set_param(NS, BOOK_PARAMS)
    ros.start(['/usr/bin/python3', FAKE, '__ns:=' + NS], name='fake_controller_manager')
    ros.wait_for_service(NS + '/controller_manager/switch_controller')
    return ros


def cli(ros, *args):
    out = ros.run(['rosrun', 'controller_manager', 'controller_manager'] + list(args)
                  + ['__ns:=' + NS])
    return out


def listing(ros):
    out = cli(ros, 'list')
    assert out.returncode == 0, out.stderr
    return out.stdout.splitlines()


def test_spawner_loads_and_starts_then_takes_down_on_sigint(manager):
    ros = manager
    spawner = ros.start(['rosrun', 'controller_manager', 'spawner', 'joint_state_controller',
                         'joint1_position_controller', '__ns:=' + NS], name='spawner',
                        may_exit=True)
    running = ['joint_state_controller -  ( running )',
               'joint1_position_controller - hardware_interface::EffortJointInterface ( running )']
    ros.wait_until(lambda: listing(ros) == running, 60, what='both controllers running')
    os.killpg(spawner.pid, signal.SIGINT)
    assert spawner.wait(timeout=60) == 0, ros.log_text(spawner)
    assert listing(ros) == ['No controllers are loaded in mechanism control']


def test_spawner_stopped_and_namespace_option(manager):
    ros = manager
    spawner = ros.start(['rosrun', 'controller_manager', 'spawner', '--stopped', '--namespace',
                         NS, 'joint_state_controller'], name='spawner', may_exit=True)
    ros.wait_until(lambda: listing(ros) == ['joint_state_controller -  ( stopped )'], 60,
                   what='controller loaded, stopped')
    ros.terminate(spawner)
    assert listing(ros) == ['No controllers are loaded in mechanism control']


def test_spawner_exits_nonzero_naming_the_controller_that_would_not_load(manager):
    ros = manager
    out = ros.run(['rosrun', 'controller_manager', 'spawner', 'joint_state_controller',
                   'no_such_controller', '__ns:=' + NS], timeout=120)
    assert out.returncode == 1
    assert "Failed to load controller 'no_such_controller'" in out.stdout + out.stderr
    # What it had loaded before the failure is unloaded again.
    assert listing(ros) == ['No controllers are loaded in mechanism control']


def test_spawner_without_a_controller_manager_gives_up_after_its_timeout(ros):
    out = ros.run(['rosrun', 'controller_manager', 'spawner', '--timeout', '1', 'x',
                   '__ns:=' + NS], timeout=120)
    assert out.returncode == 1
    assert "couldn't find the expected controller_manager" in out.stdout + out.stderr


def test_spawner_waits_for_true_on_its_wait_for_topic(manager):
    ros = manager
    ros.start(['rosrun', 'controller_manager', 'spawner', '--wait-for', '/ready',
               'joint_state_controller', '__ns:=' + NS], name='spawner', may_exit=True)

    def subscribed():
        code, _, state = ros.master().getSystemState('/test')
        return any(topic == '/ready' for topic, _ in state[1])
    ros.wait_until(subscribed, 60, what='the spawner to subscribe to /ready')
    assert listing(ros) == ['No controllers are loaded in mechanism control']
    ros.start(['rostopic', 'pub', '-l', '/ready', 'std_msgs/Bool', 'true'], name='ready')
    ros.wait_until(lambda: listing(ros) == ['joint_state_controller -  ( running )'], 60,
                   what='the controller running after True on /ready')


def test_spawner_interrupted_while_waiting_for_services_ends_at_once(ros):
    spawner = ros.start(['rosrun', 'controller_manager', 'spawner', 'joint_state_controller',
                         '__ns:=' + NS], name='spawner', may_exit=True)

    def waiting():
        return 'Waiting for service' in ros.log_text(spawner)
    ros.wait_until(waiting, 60, what='the spawner to wait for the controller manager')
    os.killpg(spawner.pid, signal.SIGINT)
    # Well inside the 30 s it would otherwise wait for the services.
    assert spawner.wait(timeout=20) == 0, ros.log_text(spawner)


def test_controller_manager_commands(manager):
    ros = manager
    assert cli(ros, 'spawn', 'joint_state_controller').stdout.splitlines() == [
        'Loaded joint_state_controller', "Started ['joint_state_controller'] successfully"]
    out = cli(ros, 'load', 'joint1_position_controller')
    assert (out.returncode, out.stdout.strip()) == (0, 'Loaded joint1_position_controller')
    assert listing(ros) == [
        'joint_state_controller -  ( running )',
        'joint1_position_controller - hardware_interface::EffortJointInterface ( stopped )']
    assert cli(ros, 'start', 'joint1_position_controller').returncode == 0
    assert cli(ros, 'stop', 'joint1_position_controller').returncode == 0
    assert cli(ros, 'unload', 'joint1_position_controller').stdout.strip() == (
        'Unloaded joint1_position_controller successfully')
    assert cli(ros, 'kill', 'joint_state_controller').returncode == 0
    assert listing(ros) == ['No controllers are loaded in mechanism control']
    out = cli(ros, 'load', 'no_such_controller')
    assert (out.returncode, out.stdout.strip()) == (1, 'Error when loading no_such_controller')
    assert cli(ros, 'list-types').stdout.splitlines() == [
        'effort_controllers/JointPositionController',
        'joint_state_controller/JointStateController']
    out = cli(ros, 'frobnicate')
    assert out.returncode == 1 and 'spawn <name>' in out.stdout
