"""ROS 1's xacro (src/xacro, PyPI's xacro with roslaunch's substitution args) on a robot of our own
making (tests/xacro_robot: $(find) of a package, macros, properties, $(arg) with a default,
$(optenv), $(eval)): the command as users type it and as launch files run it, the robot it makes
spawned into the simulator, and xacro's own errors with a failing exit status."""
import math
import os
import subprocess
import xml.etree.ElementTree as ET

import pytest

from api_client import GazeboApi
from conftest import WORKSPACE, start_sim
from onedof_harness.private_ros import COMMAND_TIMEOUT

XACRO_ROBOT = os.path.join(WORKSPACE, 'tests', 'xacro_robot')
ARM_XACRO = os.path.join(XACRO_ROBOT, 'urdf', 'arm.xacro')
XACRO = os.path.join(WORKSPACE, 'src', 'xacro', 'xacro')
DENSITY = 1000.0


@pytest.fixture
def xacro_env(tmp_path):
    """This environment with xacro_robot on ROS_PACKAGE_PATH and a PATH whose python3 cannot
    import ROS (as pyenv's on the developers' machines; a user's Debian has its own there)."""
    shim = tmp_path / 'python3'
    shim.write_text('#!/bin/sh\necho "foreign python3 was used: $0 $*" >&2\nexit 97\n')
    shim.chmod(0o755)
    env = dict(os.environ, PATH='%s:%s' % (tmp_path, os.environ['PATH']),
               ROS_PACKAGE_PATH='%s:%s' % (XACRO_ROBOT, os.environ['ROS_PACKAGE_PATH']))
    env.pop('XACRO_ARM_RGBA', None)
    return env


def run(command, env, cwd=None, timeout=COMMAND_TIMEOUT):
    return subprocess.run(command, env=env, cwd=cwd, capture_output=True, text=True,
                          timeout=timeout)


def box_inertia(x, y, z):
    mass = DENSITY * x * y * z
    return mass, (mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12,
                  mass * (x * x + y * y) / 12)


def check_arm(urdf_text, arm_length, arm_rgba):
    """The robot arm.xacro describes, computed here from its figures, not read from xacro."""
    robot = ET.fromstring(urdf_text)
    assert robot.get('name') == 'xacro_arm'
    assert [link.get('name') for link in robot.iter('link')] == ['world', 'pedestal', 'arm']
    for name, size, rgba in (('pedestal', (0.2, 0.2, 0.4), '0.5 0.5 0.5 1'),
                             ('arm', (0.1, 0.1, arm_length), arm_rgba)):
        link = robot.find("link[@name='%s']" % name)
        mass, (ixx, iyy, izz) = box_inertia(*size)
        assert float(link.find('inertial/mass').get('value')) == pytest.approx(mass)
        inertia = link.find('inertial/inertia')
        assert [float(inertia.get(k)) for k in ('ixx', 'iyy', 'izz')] == pytest.approx(
            [ixx, iyy, izz])
        for element in ('inertial', 'visual', 'collision'):
            origin = link.find(element + '/origin')
            assert [float(v) for v in origin.get('xyz').split()] == pytest.approx(
                [0, 0, size[2] / 2])
        for element in ('visual', 'collision'):
            box = link.find(element + '/geometry/box')
            assert [float(v) for v in box.get('size').split()] == pytest.approx(list(size))
        assert link.find('visual/material/color').get('rgba') == rgba
    shoulder = robot.find("joint[@name='shoulder']")
    assert shoulder.get('type') == 'revolute'
    assert (shoulder.find('parent').get('link'), shoulder.find('child').get('link')) == (
        'pedestal', 'arm')
    assert [float(v) for v in shoulder.find('origin').get('xyz').split()] == pytest.approx(
        [0, 0, 0.4])
    limit = shoulder.find('limit')
    assert (float(limit.get('lower')), float(limit.get('upper'))) == pytest.approx(
        (-math.pi / 2, math.pi / 2))


def test_rosrun_xacro_converts_with_find_macros_properties_and_arg_default(xacro_env, tmp_path):
    result = run(['rosrun', 'xacro', 'xacro', ARM_XACRO], xacro_env)
    assert result.returncode == 0, result.stderr
    assert 'foreign python3 was used' not in result.stderr
    check_arm(result.stdout, arm_length=0.5, arm_rgba='1 0 0 1')
    urdf = tmp_path / 'arm.urdf'
    urdf.write_text(result.stdout)
    check = run(['check_urdf', str(urdf)], xacro_env)
    assert check.returncode == 0, check.stdout + check.stderr


def test_command_line_args_and_environment_set_the_robot(xacro_env, tmp_path):
    """`name:=value` sets $(arg name); $(optenv) reads the environment; -o writes a file."""
    out = tmp_path / 'arm.urdf'
    result = run([XACRO, ARM_XACRO, 'arm_length:=0.75', '-o', str(out)],
                 dict(xacro_env, XACRO_ARM_RGBA='0 0 1 1'))
    assert result.returncode == 0, result.stderr
    check_arm(out.read_text(), arm_length=0.75, arm_rgba='0 0 1 1')


def test_older_name_and_env_substitution(xacro_env):
    """xacro.py (the name older launch files run) is the same command; $(env NAME) reads the
    environment and, unset, is an error naming the variable, as ROS 1's xacro has it."""
    env_xacro = os.path.join(XACRO_ROBOT, 'urdf', 'env.xacro')
    result = run([XACRO + '.py', env_xacro], dict(xacro_env, XACRO_ROBOT_NAME='named_by_env'))
    assert result.returncode == 0, result.stderr
    assert ET.fromstring(result.stdout).get('name') == 'named_by_env'
    unset = run([XACRO, env_xacro], xacro_env)
    assert unset.returncode != 0
    assert "environment variable 'XACRO_ROBOT_NAME' is not set" in unset.stderr


def xacro_file(tmp_path, body, name='bad.xacro'):
    path = tmp_path / name
    path.write_text('<?xml version="1.0"?>\n<robot name="bad" '
                    'xmlns:xacro="http://www.ros.org/wiki/xacro">%s</robot>\n' % body)
    return str(path)


@pytest.mark.parametrize('body, message', [
    ('<xacro:wheel/>', 'unknown macro name: xacro:wheel'),
    ('<xacro:include filename="$(find nosuchpkg)/robot.xacro"/>', 'ResourceNotFound'),
    ('<link name="$(arg no_such_arg)"/>', 'Undefined substitution argument no_such_arg'),
    # ROS 1's xacro gives roslaunch no file name for $(dirname): an error there too.
    ('<link name="$(dirname)"/>', 'Cannot substitute $(dirname)'),
], ids=['unknown macro', 'unknown package', 'undefined arg', 'dirname'])
def test_errors_are_xacros_with_a_failing_status(xacro_env, tmp_path, body, message):
    result = run([XACRO, xacro_file(tmp_path, body)], xacro_env)
    assert result.returncode != 0
    assert message in result.stderr, result.stderr
    assert result.stdout == ''
    if 'nosuchpkg' in body:
        assert 'nosuchpkg' in result.stderr


def test_missing_file_is_an_error_naming_it(xacro_env, tmp_path):
    result = run([XACRO, str(tmp_path / 'no_such_robot.xacro')], xacro_env)
    assert result.returncode != 0
    assert 'No such file or directory' in result.stderr
    assert 'no_such_robot.xacro' in result.stderr


def test_launch_file_command_loads_the_robot_and_spawns_it(ros, rospy_client, xacro_env):
    """spawn.launch as the book's launch files do it: robot_description from
    command="$(find xacro)/xacro '$(find xacro_robot)/urdf/arm.xacro' ...", then spawn_model
    -param robot_description; the robot is in the simulator with the joints of the file."""
    ros.env['ROS_PACKAGE_PATH'] = xacro_env['ROS_PACKAGE_PATH']
    ros.env['PATH'] = xacro_env['PATH']
    start_sim(ros)
    ros.start(['roslaunch', 'xacro_robot', 'spawn.launch', 'arm_length:=0.6'],
              name='roslaunch', may_exit=True)
    api = GazeboApi(rospy_client)
    ros.wait_until(lambda: 'xacro_arm' in api.get_world_properties().model_names, 120,
                   what='xacro_arm spawned')
    check_arm(rospy_client.get_param('/robot_description'), arm_length=0.6, arm_rgba='1 0 0 1')
    shoulder = api.get_joint_properties('shoulder')
    assert shoulder.success, shoulder.status_message


def test_launch_file_with_a_bad_xacro_stops_with_xacros_error(ros, xacro_env, tmp_path):
    bad = xacro_file(tmp_path, '<xacro:wheel/>')
    launch = tmp_path / 'bad.launch'
    launch.write_text('<launch>\n  <param name="robot_description" '
                      'command="$(find xacro)/xacro \'%s\'"/>\n</launch>\n' % bad)
    ros.env['PATH'] = xacro_env['PATH']
    result = ros.run(['roslaunch', str(launch)])
    assert result.returncode != 0
    output = result.stdout + result.stderr
    assert 'unknown macro name: xacro:wheel' in output, output
    assert 'Cannot load command parameter [robot_description]' in output, output
