"""The workspace as a new user meets it: idempotent set-up, commands that resolve to our packages
under a Python that can import rospy, clean package manifests, and a docker/ that only wraps what
these tests exercise."""
import ipaddress
import os
import re
import shlex
import subprocess

import pytest
import yaml

from conftest import WORKSPACE
from onedof_harness.private_ros import BIND_LIBRARY, wait_until

DEVEL = next(p for p in os.environ['CMAKE_PREFIX_PATH'].split(':')
             if os.path.isfile(os.path.join(p, '.catkin')))
BUILD = re.sub(r'^devel', 'build', os.path.basename(DEVEL))


def make_dry_run(target):
    return subprocess.run(['make', '-n', '-C', WORKSPACE, target, 'BUILD=' + BUILD,
                           'DEVEL=' + os.path.basename(DEVEL)],
                          capture_output=True, text=True, check=True).stdout


def test_second_setup_installs_and_builds_nothing():
    plan = make_dry_run('setup')
    # `deps` always asks dpkg (a fraction of a second); it must decide that nothing is missing.
    deps = subprocess.run(['make', '-C', WORKSPACE, 'deps'], capture_output=True, text=True)
    assert deps.returncode == 0, deps.stderr
    assert 'installing' not in deps.stdout
    assert 'catkin_make' not in plan and 'pip install' not in plan, plan


@pytest.fixture
def foreign_python3(tmp_path):
    """A PATH whose python3 cannot import rospy (as pyenv's on the developers' machines)."""
    shim = tmp_path / 'python3'
    shim.write_text('#!/bin/sh\necho "foreign python3 was used: $0 $*" >&2\nexit 97\n')
    shim.chmod(0o755)
    return dict(os.environ, PATH='%s:%s' % (tmp_path, os.environ['PATH']))


@pytest.mark.parametrize('command', [
    ['rosrun', 'onedof_sim', 'spawn_model', '-h'],
    ['rosrun', 'onedof_sim', 'plot', '-h'],
    ['rosrun', 'minimal_joint_controller', 'minimal_joint_controller', '-h'],
    ['rostopic', 'list', '-h'],
    ['rosservice', 'list', '-h'],
    ['roslaunch', '-h'],
])
def test_tutorial_commands_run_under_a_python_with_rospy(foreign_python3, command):
    result = subprocess.run(command, env=foreign_python3, capture_output=True, text=True,
                            timeout=300)
    assert 'foreign python3 was used' not in result.stderr
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize('package', ['onedof_sim', 'minimal_joint_controller',
                                     'minimal_robot_description'])
def test_packages_resolve_to_this_workspace(package):
    path = subprocess.run(['rospack', 'find', package], capture_output=True, text=True,
                          check=True).stdout.strip()
    assert path == os.path.join(WORKSPACE, 'src', package)


def test_catkin_lint_is_clean():
    result = subprocess.run(['catkin_lint', '-W1', '--strict', os.path.join(WORKSPACE, 'src')],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


def test_dockerfile_runs_the_make_targets_ci_runs():
    text = open(os.path.join(WORKSPACE, 'docker', 'Dockerfile')).read()
    assert 'FROM debian:bookworm' in text
    assert re.search(r'^RUN \./run setup\b', text, re.M)
    assert re.search(r'^CMD \["\./run", "tutorial"\]', text, re.M)
    for target in ('setup', 'tutorial'):
        make_dry_run(target)  # raises if the target does not exist


def compose():
    with open(os.path.join(WORKSPACE, 'docker', 'compose.yaml')) as f:
        return yaml.safe_load(f)


def test_compose_is_the_two_hosts_set_up():
    """docker/compose.yaml puts the simulator and the controller where tests/test_two_hosts.py
    puts them: one network, ROS_MASTER_URI at the sim service, ROS_IP each its own address, and
    the bind library (built in the image's workspace) preloaded."""
    from test_two_hosts import CONTROLLER_ADDRESS, PREFIX_LENGTH, SIM_ADDRESS
    with open(os.path.join(WORKSPACE, 'docker', 'Dockerfile')) as f:
        workdir = re.search(r'^WORKDIR (\S+)', f.read(), re.M).group(1)
    services = compose()['services']
    assert set(services) == {'sim', 'controller'}
    for name, address in (('sim', SIM_ADDRESS), ('controller', CONTROLLER_ADDRESS)):
        assert services[name]['networks'] == {'ros': {'ipv4_address': address}}
        assert services[name]['environment'] == {
            'ROS_MASTER_URI': 'http://%s:11311' % SIM_ADDRESS, 'ROS_IP': address,
            'LD_PRELOAD': os.path.join(workdir, 'devel', 'lib', BIND_LIBRARY)}
    subnet = ipaddress.ip_network('%s/%d' % (SIM_ADDRESS, PREFIX_LENGTH), strict=False)
    assert compose()['networks']['ros']['ipam']['config'][0]['subnet'] == str(subnet)


def test_compose_services_commands_bring_up_the_controlled_robot(ros, rospy_client):
    """Runs the simulator and controller services' commands as compose would, against a private
    roscore (the compose file's addresses replaced by this graph's)."""
    rospy = rospy_client
    from std_msgs.msg import Float64
    for name in ('sim', 'controller'):
        command = compose()['services'][name]['command']
        assert command[:2] == ['bash', '-c']
        ros.start(['bash', '-c', command[2]], name='compose_' + name)
    positions = []
    rospy.Subscriber('/jnt_pos', Float64, lambda msg: positions.append(msg.data))
    wait_until(lambda: len(positions) > 10, 90, what='jnt_pos from the composed controller')


def required_commands():
    with open(os.path.join(WORKSPACE, 'scripts', 'required-commands')) as f:
        return {line.split()[0] for line in f if line.strip() and not line.startswith('#')}


# The shell's own and coreutils' commands, on every Debian machine.
ESSENTIAL_COMMANDS = {'bash', 'sh', 'sleep', 'true'}


def test_every_command_the_code_runs_is_installed_by_the_set_up():
    """The first word of each command list the Python code and tests hand to subprocess or to a
    graph's start() is in scripts/required-commands, which `make setup` checks."""
    files = subprocess.run(['git', 'ls-files', '*.py', 'src/*/scripts/*'], cwd=WORKSPACE,
                           capture_output=True, text=True, check=True).stdout.split()
    run = re.compile(r"(?:subprocess\.(?:run|Popen|check_output|check_call|call)\(|start\(|"
                     r"command\s*=\s*)\s*\[\s*'([^']+)'")
    commands = {}
    for name in files:
        with open(os.path.join(WORKSPACE, name), errors='replace') as f:
            for command in run.findall(f.read()):
                commands.setdefault(command, name)
    assert {'ip', 'ss', 'rosrun', 'Xvfb', 'import'} <= set(commands)  # the scan finds them
    unlisted = {command: name for command, name in commands.items()
                if command not in required_commands() | ESSENTIAL_COMMANDS}
    assert not unlisted, 'run but not in scripts/required-commands: %s' % unlisted


def test_set_up_fails_naming_a_missing_command(tmp_path):
    listed = tmp_path / 'required-commands'
    listed.write_text('# command  provided by\nrosrun rosbash\nno_such_command_here iproute2\n')
    result = subprocess.run(['make', '-C', WORKSPACE, 'commands', 'BUILD=' + BUILD,
                             'DEVEL=' + os.path.basename(DEVEL),
                             'REQUIRED_COMMANDS=%s' % listed], capture_output=True, text=True)
    assert result.returncode != 0
    assert 'no_such_command_here (iproute2)' in result.stdout
    assert 'rosrun' not in result.stdout
