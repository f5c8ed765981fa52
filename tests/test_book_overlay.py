"""A package in the shape of the book's minimal_robot_description (learning_ros, Part_2), of our
own making (tests/book_shaped): the same package name and launch file names, and the same ROS
features (an included empty_world.launch, spawn_model from a parameter, controllers from a YAML
started by the spawner, a robot converted by `$(find xacro)/xacro` from a xacro that includes
macros by `$(find)`), over robots written for this test. Built in an overlay on this workspace, as
the README's recipe builds the book's: it shadows ours, and its launch files start the simulator,
spawn the robot and run its controllers.

The overlay is built once for the session's tests: a folder beside the workers' own, under a
lock (book_client.shared_overlay)."""
import os
import subprocess

import pytest

from api_client import ROBOT, GazeboApi, ros_duration, ros_time
from conftest import OVERLAY_TESTS_TIMEOUT, session_folder, start_sim
from controller_manager_cli import (BOOK_CONTROLLERS_RUNNING, NS, STATE_CONTROLLER_RUNNING,
                                     wait_for_listing)
from onedof_harness import book_client
from onedof_harness.private_ros import COMMAND_TIMEOUT

pytestmark = OVERLAY_TESTS_TIMEOUT

BOOK_PACKAGE = os.path.join('book_shaped', 'minimal_robot_description')


@pytest.fixture
def overlay(tmp_path_factory):
    """The overlay's setup.bash."""
    folder = session_folder(tmp_path_factory, 'book_minimal_robot_description')
    return book_client.shared_overlay(folder, packages=(BOOK_PACKAGE,))


# What `controller_manager list` prints for the velocity launch file's controllers, running.
VELOCITY_CONTROLLERS_RUNNING = [
    STATE_CONTROLLER_RUNNING,
    'joint1_velocity_controller - hardware_interface::EffortJointInterface ( running )']


def in_overlay(setup, *command):
    return ['bash', '-c', 'source %s && exec "$@"' % setup, 'overlay'] + list(command)


def test_the_overlays_package_shadows_ours(overlay):
    # rospack reads the package path, no roscore.
    found = subprocess.run(in_overlay(overlay, 'rospack', 'find', 'minimal_robot_description'),
                           capture_output=True, text=True, timeout=COMMAND_TIMEOUT)
    assert found.returncode == 0, found.stderr
    overlay_root = os.path.dirname(os.path.dirname(overlay))  # <overlay>/devel/setup.bash
    assert found.stdout.strip() == os.path.join(overlay_root, 'src', 'minimal_robot_description')


def robot_responds(ros, api):
    """The spawned robot's joint1 turns under an effort applied now (upright, gravity alone
    would not tip it)."""
    ros.wait_until(lambda: ROBOT in api.get_world_properties().model_names, 120,
                   what=ROBOT + ' spawned')
    api.unpause_physics()
    start = api.get_joint_properties('joint1').position[0]
    api.apply_joint_effort('joint1', 5.0, ros_time(api.sim_time_ns()), ros_duration(10 ** 9))
    ros.wait_until(lambda: abs(api.get_joint_properties('joint1').position[0] - start) > 0.01,
                   120, what='joint1 to move')


def test_minimal_robot_description_launch_starts_the_simulator_and_spawns(
        ros, rospy_client, overlay):
    ros.start(in_overlay(overlay, 'roslaunch', 'minimal_robot_description',
                         'minimal_robot_description.launch', 'gui:=false'), name='roslaunch')
    ros.wait_until(lambda: ros.has_service('/gazebo/get_world_properties'), 120,
                   what='the simulator the launch file starts')
    robot_responds(ros, GazeboApi(rospy_client))


def test_minimal_robot_w_jnt_ctl_launch_runs_the_books_controllers(ros, rospy_client, overlay):
    ros.start(in_overlay(overlay, 'roslaunch', 'minimal_robot_description',
                         'minimal_robot_w_jnt_ctl.launch'), name='roslaunch')
    wait_for_listing(ros, rospy_client, BOOK_CONTROLLERS_RUNNING, timeout=180,
                     what='the book launch file\'s two controllers running')
    api = GazeboApi(rospy_client)
    ros.start(['rostopic', 'pub', NS + '/joint1_position_controller/command',
               'std_msgs/Float64', '1.0'], name='rostopic_pub')
    # The world runs in real time while the launch file starts its nodes and as fast as it can
    # from the command on: the settling's sim time (about 100 s) in a few wall seconds.
    api.set_physics(max_update_rate=0)
    ros.wait_until(lambda: abs(api.get_joint_properties('joint1').position[0] - 1.0) < 0.05,
                   180, what='joint1 to come to the commanded 1.0 rad')


def test_prismatic_robot_from_xacro_spawns_with_its_velocity_controller(
        ros, rospy_client, overlay):
    """prismatic_1dof_robot_w_jnt_ctl.launch converts its robot with `$(find xacro)/xacro` and
    spawns it into a running simulator, as the book's runs after empty_world.launch."""
    start_sim(ros)
    ros.start(in_overlay(overlay, 'roslaunch', 'minimal_robot_description',
                         'prismatic_1dof_robot_w_jnt_ctl.launch'), name='roslaunch')
    api = GazeboApi(rospy_client)
    ros.wait_until(lambda: ROBOT in api.get_world_properties().model_names, 120,
                   what='the prismatic robot spawned')
    assert api.get_joint_properties('joint1').success
    wait_for_listing(ros, rospy_client, VELOCITY_CONTROLLERS_RUNNING, timeout=180,
                     what='the velocity controller running')
