"""Debian's joint_state_publisher, a ROS Python script run as `#!/usr/bin/env python3`, launched
as the book's lidar_wobbler.launch launches it (its joint_states remapped into the robot's
namespace), publishes the robot's joint states in a shell that sources this workspace, whichever
python3 comes first on PATH: one that cannot find rospy (as pyenv's; here a Python without its
site packages) is put behind the workspace's (src/onedof_sim/env-hooks/50.ros_python.sh), and
Debian's is left first."""
import os
import subprocess

import pytest

from onedof_harness.private_ros import COMMAND_TIMEOUT

ROBOT = """<robot name="wobbler">
  <link name="base_link"/>
  <link name="lidar_link">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/><child link="lidar_link"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
  </joint>
</robot>
"""

LAUNCH = """<launch>
  <param name="robot_description" textfile="%s"/>
  <node name="joint_state_publisher" pkg="joint_state_publisher" type="joint_state_publisher">
    <remap from="joint_states" to="/wobbler/joint_states"/>
  </node>
</launch>
"""

# A python3 that cannot import rospy: Debian's without its site packages.
PYTHON_WITHOUT_ROSPY = '#!/bin/sh\nexec /usr/bin/python3 -S "$@"\n'


def workspace_setup():
    """This workspace's devel/setup.bash: the prefix on CMAKE_PREFIX_PATH holding its ros_python
    folder."""
    for prefix in os.environ.get('CMAKE_PREFIX_PATH', '').split(':'):
        if os.path.isdir(os.path.join(prefix, 'lib', 'onedof_sim', 'ros_python')):
            return os.path.join(prefix, 'setup.bash')
    pytest.fail('no prefix on CMAKE_PREFIX_PATH holds lib/onedof_sim/ros_python: source the '
                'workspace\'s devel/setup.bash')


def first_python(tmp_path, kind):
    """A folder to put first on PATH, holding a `python3` of the kind asked for."""
    folder = tmp_path / kind
    folder.mkdir()
    python3 = folder / 'python3'
    if kind == 'without_rospy':
        python3.write_text(PYTHON_WITHOUT_ROSPY)
        python3.chmod(0o755)
    else:
        python3.symlink_to('/usr/bin/python3')
    return str(folder)


def in_shell(first, command):
    """command in a shell whose PATH starts with `first`, then sources this workspace."""
    return ['bash', '-c', 'export PATH="$1:$PATH" && source "$2" && %s' % command, '-', first,
            workspace_setup()]


@pytest.mark.parametrize('kind', ['without_rospy', 'debians'])
def test_the_books_joint_state_publisher_publishes_whichever_python3_is_first(
        ros, rospy_client, tmp_path, kind):
    from sensor_msgs.msg import JointState
    first = first_python(tmp_path, kind)
    can_import = subprocess.run([os.path.join(first, 'python3'), '-c', 'import rospy'],
                                capture_output=True)
    assert (can_import.returncode == 0) == (kind == 'debians')

    resolved = subprocess.run(in_shell(first, 'command -v python3'), capture_output=True,
                              text=True, timeout=COMMAND_TIMEOUT)
    assert resolved.returncode == 0, resolved.stderr
    if kind == 'debians':
        assert resolved.stdout.strip() == os.path.join(first, 'python3')
    else:
        assert resolved.stdout.strip().endswith('/lib/onedof_sim/ros_python/python3')

    robot = tmp_path / 'wobbler.urdf'
    robot.write_text(ROBOT)
    launch = tmp_path / 'wobbler.launch'
    launch.write_text(LAUNCH % robot)
    launched = ros.start(in_shell(first, 'exec roslaunch "%s"' % launch), name='roslaunch')

    def received():
        try:
            return rospy_client.wait_for_message('/wobbler/joint_states', JointState, timeout=5)
        except rospy_client.ROSException:
            return None
    message = ros.wait_until(received, timeout=300, what='/wobbler/joint_states')
    assert list(message.name) == ['joint1']
    assert list(message.position) == [0.0]
    assert 'No module named' not in ros.log_text(launched)
