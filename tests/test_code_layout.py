"""The layering and size rules the code keeps (README, How it works): the physics core, the
control library and the camera renderer are free of ROS and never include the ROS layer; gazebo_api.cpp holds the
handlers only; no product source file grows past a screenful of screens."""
import os
import re
import subprocess

import pytest

from conftest import WORKSPACE

PACKAGE = os.path.join('src', 'onedof_sim')
ROS_FREE = [os.path.join(PACKAGE, 'src', 'core'), os.path.join(PACKAGE, 'src', 'control'),
            os.path.join(PACKAGE, 'src', 'render'), os.path.join(PACKAGE, 'include')]
# ROS headers and message packages a ROS-free file must not include.
ROS_INCLUDE = re.compile(r'#include\s*[<"](ros/|roscpp|std_msgs/|sensor_msgs/|geometry_msgs/|'
                         r'gazebo_msgs/|control_msgs/|controller_manager_msgs/|rosgraph_msgs/|'
                         r'dynamic_reconfigure/|visualization_msgs/|onedof_sim/StepSimulation)')
MAX_LINES = 1000
MAX_API_LINES = 800


def tracked(*patterns):
    return subprocess.run(['git', 'ls-files', '--'] + list(patterns), cwd=WORKSPACE,
                          capture_output=True, text=True, check=True).stdout.split()


def lines_of(path):
    with open(os.path.join(WORKSPACE, path), errors='replace') as f:
        return f.read().splitlines()


@pytest.mark.parametrize('folder', ROS_FREE)
def test_the_core_and_the_control_library_include_nothing_of_ros(folder):
    files = tracked(folder + '/*.h', folder + '/*.cpp')
    assert files, folder
    for path in files:
        for number, line in enumerate(lines_of(path), 1):
            assert not ROS_INCLUDE.search(line), '%s:%d: %s' % (path, number, line)
            included = re.match(r'#include\s*"([^"]+)"', line)
            if included:
                target = os.path.normpath(os.path.join(os.path.dirname(path), included.group(1)))
                assert os.sep + 'ros' + os.sep not in os.sep + target, \
                    '%s:%d includes the ROS layer: %s' % (path, number, line)


def test_no_product_source_file_is_longer_than_a_thousand_lines():
    sources = [path for path in tracked('src/*.cpp', 'src/*.h', 'src/*.py', 'src/*.c')
               if '/test/' not in path]
    assert sources
    long = {path: len(lines_of(path)) for path in sources if len(lines_of(path)) > MAX_LINES}
    assert not long, long


def test_gazebo_api_holds_the_handlers_only():
    path = os.path.join(PACKAGE, 'src', 'ros', 'gazebo_api.cpp')
    assert len(lines_of(path)) < MAX_API_LINES
