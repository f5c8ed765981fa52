"""The tools the book's steps call beside the simulator, installed by the set-up: tf's
command-line tools on a running robot_state_publisher (the tutorial robot), image_view, and
Eigen 3 for the book's C++ packages (a catkin package that finds it as they do builds and runs)."""
import math
import os
import re
import subprocess

import pytest

from conftest import OVERLAY_TESTS_TIMEOUT, TUTORIAL_URDF
from onedof_harness import book_client

pytestmark = OVERLAY_TESTS_TIMEOUT


@pytest.fixture
def tutorial_robot_frames(ros, rospy_client):
    """robot_state_publisher on the tutorial robot, fed joint1 = 0.5 on /joint_states, each
    message stamped when it is sent (-s: rostopic pub takes `now` once without it, and
    robot_state_publisher sends a joint's transform only when its stamp moves on)."""
    from sensor_msgs.msg import JointState
    with open(TUTORIAL_URDF) as f:
        ros.set_param('/robot_description', f.read())
    ros.start(['rosrun', 'robot_state_publisher', 'robot_state_publisher'],
              name='robot_state_publisher')
    ros.start(['rostopic', 'pub', '-s', '-r', '20', '/joint_states', 'sensor_msgs/JointState',
               '{header: {stamp: now}, name: [joint1], position: [0.5]}'], name='joint_states')
    return 0.5


def test_tf_echo_and_tf_monitor_reach_the_robot_state_publishers_frames(ros,
                                                                       tutorial_robot_frames):
    """`rosrun tf tf_echo world link2`: link2 sits 1 m above the world, turned by joint1 about y,
    in transforms that keep coming (tf_echo prints the latest once a second, each later);
    `rosrun tf tf_monitor` lists the robot's frames. Both on the one robot_state_publisher."""
    q = tutorial_robot_frames
    echo = ros.start(['rosrun', 'tf', 'tf_echo', 'world', 'link2'], name='tf_echo')
    monitor = ros.start(['rosrun', 'tf', 'tf_monitor'], name='tf_monitor')
    number = r'([-\d.]+)'
    pattern = re.compile(r'At time ([\d.]+)\s*- Translation: \[%s, %s, %s\]\s*'
                         r'- Rotation: in Quaternion \[%s, %s, %s, %s\]' % ((number,) * 7))
    ros.wait_until(lambda: len(pattern.findall(ros.log_text(echo))) >= 2, 90,
                   what='tf_echo to print world -> link2 twice')
    prints = [[float(v) for v in found] for found in pattern.findall(ros.log_text(echo))]
    assert prints[1][0] > prints[0][0], 'the transform is not renewed: %s' % prints[:2]
    values = prints[-1][1:]
    assert values[:3] == pytest.approx([0, 0, 1], abs=1e-3)
    assert values[3:] == pytest.approx([0, math.sin(q / 2), 0, math.cos(q / 2)], abs=1e-3)

    # robot_state_publisher broadcasts through tf2, which does not tell tf_monitor its name.
    ros.wait_until(lambda: 'Frame: link2 published by' in ros.log_text(monitor)
                   and 'Frame: link1 published by' in ros.log_text(monitor), 90,
                   what='tf_monitor to list link1 and link2')


def test_image_view_is_where_rosrun_finds_it(ros):
    """image_view needs an image topic and a display: here, the two look-ups `rosrun image_view
    image_view` makes (the package's manifest, its executable) find it."""
    found = ros.run(['rospack', 'find', 'image_view'])
    assert found.returncode == 0, found.stderr
    located = ros.run(['catkin_find', '--libexec', 'image_view', 'image_view'])
    assert located.returncode == 0, located.stderr
    assert os.access(located.stdout.strip(), os.X_OK), located.stdout


def test_a_catkin_package_using_eigen3_builds_and_runs(tmp_path):
    """tests/eigen_package finds Eigen 3 as the book's packages do (cmake_modules, then
    find_package(Eigen3)); built in an overlay, it fits the normal of the plane z = x."""
    setup = book_client.build_overlay(tmp_path, packages=('eigen_package',))
    points = ['0', '0', '0', '1', '0', '1', '0', '1', '0', '1', '1', '1', '2', '3', '2']
    result = subprocess.run(['bash', '-c', 'source %s && rosrun eigen_package plane_normal %s'
                             % (setup, ' '.join(points))], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr
    normal = [float(v) for v in result.stdout.split()]
    assert normal == pytest.approx([-math.sqrt(0.5), 0, math.sqrt(0.5)], abs=1e-6)
