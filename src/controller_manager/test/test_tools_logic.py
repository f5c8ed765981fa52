from types import SimpleNamespace

import pytest

from controller_manager import controller_manager_interface as cmi
from controller_manager.cli import plan
from controller_manager.naming import service_name
from controller_manager.spawner import (expand_controller_args, load_all, load_failure_message,
                                        parse_args, take_down)
from controller_manager.unspawner import running_to_stop


def test_service_names_are_relative_unless_a_namespace_is_given():
    assert service_name(None, 'load_controller') == 'controller_manager/load_controller'
    assert service_name('', 'list_controllers') == 'controller_manager/list_controllers'
    assert service_name('/one_DOF_robot', 'switch_controller') == (
        '/one_DOF_robot/controller_manager/switch_controller')
    assert service_name('robot/', 'unload_controller') == (
        'robot/controller_manager/unload_controller')


def test_spawner_takes_ros_controls_options():
    args = parse_args(['--stopped', '--wait-for', '/ready', '--namespace', '/r', '--timeout', '5',
                       '--shutdown-timeout', '2.5', 'a', 'b'])
    assert (args.stopped, args.wait_for, args.namespace) == (True, '/ready', '/r')
    assert (args.timeout, args.shutdown_timeout, args.controllers) == (5.0, 2.5, ['a', 'b'])
    defaults = parse_args(['joint_state_controller'])
    assert (defaults.stopped, defaults.wait_for, defaults.namespace) == (False, None, None)
    assert (defaults.timeout, defaults.shutdown_timeout) == (30.0, 30.0)


def test_spawner_needs_a_controller(capsys):
    with pytest.raises(SystemExit) as exit_info:
        parse_args([])
    assert exit_info.value.code == 2
    assert 'controller' in capsys.readouterr().err


def test_yaml_file_arguments_name_their_controllers_in_order():
    files = {'ctl.yaml': {'jsc': {'type': 'joint_state_controller/JointStateController'},
                          'pos': {'type': 'effort_controllers/JointPositionController'}}}
    names, documents = expand_controller_args(['first', 'ctl.yaml', 'last'],
                                              is_file=files.__contains__, read_yaml=files.get)
    assert names == ['first', 'jsc', 'pos', 'last']
    assert documents == [files['ctl.yaml']]


def test_a_yaml_file_that_is_not_a_mapping_is_refused_naming_it():
    with pytest.raises(ValueError, match='bad.yaml'):
        expand_controller_args(['bad.yaml'], is_file=lambda _: True, read_yaml=lambda _: [1, 2])


def test_loading_stops_at_the_first_failure():
    calls = []

    def load(name):
        calls.append(name)
        return name != 'bad'
    assert load_all(['a', 'b'], load) == (['a', 'b'], None)
    calls.clear()
    assert load_all(['a', 'bad', 'c'], load) == (['a'], 'bad')
    assert calls == ['a', 'bad']


def test_load_failure_message_names_controller_manager_and_parameter():
    text = load_failure_message('joint1_position_controller', '/one_DOF_robot/controller_manager')
    assert "'joint1_position_controller'" in text
    assert '/one_DOF_robot/controller_manager' in text
    assert 'joint1_position_controller/type' in text


def test_take_down_stops_all_in_one_switch_then_unloads_in_reverse():
    calls = []
    stuck = take_down(['jsc', 'pos'],
                      switch=lambda start, stop: calls.append(('switch', start, stop)) or True,
                      unload=lambda name: calls.append(('unload', name)) or name != 'jsc')
    assert calls == [('switch', [], ['jsc', 'pos']), ('unload', 'pos'), ('unload', 'jsc')]
    assert stuck == ['jsc']
    calls.clear()
    assert take_down([], switch=None, unload=None) == []


def controller(name, state, *interfaces):
    return SimpleNamespace(name=name, state=state, claimed_resources=[
        SimpleNamespace(hardware_interface=i, resources=['joint1']) for i in interfaces])


def test_list_prints_ros_controls_lines():
    assert cmi.controller_lines([]) == ['No controllers are loaded in mechanism control']
    assert cmi.controller_lines([
        controller('joint1_position_controller', 'running',
                   'hardware_interface::EffortJointInterface'),
        controller('joint_state_controller', 'stopped')]) == [
        'joint1_position_controller - hardware_interface::EffortJointInterface ( running )',
        'joint_state_controller -  ( stopped )']


def test_switch_reports():
    assert cmi.switch_report(['a'], True, True) == "Started ['a'] successfully"
    assert cmi.switch_report(['a'], False, True) == "Stopped ['a'] successfully"
    assert cmi.switch_report(['a'], True, False) == "Error when starting ['a']"


@pytest.mark.parametrize('args, calls', [
    ([], []),
    (['list'], [('list_controllers', None)]),
    (['lc'], [('list_controllers', None)]),
    (['list-types'], [('list_controller_types', None)]),
    (['reload-libraries', '--restore'], [('reload_libraries', True)]),
    (['reload-libraries'], [('reload_libraries', False)]),
    (['load', 'a', 'b'], [('load_controller', 'a'), ('load_controller', 'b')]),
    (['start', 'a'], [('start_controller', 'a')]),
    (['spawn', 'a', 'b'], [('load_controller', 'a'), ('load_controller', 'b'),
                           ('start_controller', 'a'), ('start_controller', 'b')]),
    (['kl', 'a'], [('stop_controller', 'a'), ('unload_controller', 'a')]),
    (['frobnicate'], None),
])
def test_command_line_plans_ros_controls_calls(args, calls):
    assert plan(args) == calls


def test_unspawner_stops_only_named_running_controllers():
    listed = [controller('a', 'running'), controller('b', 'stopped'), controller('c', 'running')]
    assert running_to_stop(listed, ['a', 'b']) == ['a']
