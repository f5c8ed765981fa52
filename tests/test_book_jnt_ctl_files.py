"""The book's files for the robot driven by ros_control controllers (learning_ros,
minimal_robot_description): the URDF variant with <transmission> and the gazebo_ros_control tag,
the controller YAML, and minimal_robot_w_jnt_ctl.launch run as printed against the simulator,
whose own controller manager (src/onedof_sim/src/ros/control) runs the book's controllers: the
robot holds the angle commanded as the book commands it."""

import os
import xml.etree.ElementTree as ET

import yaml

from api_client import ROBOT, GazeboApi
from conftest import TUTORIAL_URDF, WORKSPACE
from controller_manager_cli import BOOK_CONTROLLERS_RUNNING, NS, wait_for_listing
from onedof_harness.private_ros import wait_until

DESCRIPTION_DIR = os.path.join(WORKSPACE, 'src', 'minimal_robot_description')
JNT_CTL_URDF = os.path.join(DESCRIPTION_DIR, 'minimal_robot_description_w_jnt_ctl.urdf')
BOOK_YAML = os.path.join(DESCRIPTION_DIR, 'control_config', 'one_dof_ctl_params.yaml')
# What the book's YAML holds, in its namespace.
BOOK_PARAMS = {
    'joint_state_controller': {'type': 'joint_state_controller/JointStateController',
                               'publish_rate': 50},
    'joint1_position_controller': {'type': 'effort_controllers/JointPositionController',
                                   'joint': 'joint1',
                                   'pid': {'p': 10.0, 'i': 10.0, 'd': 10.0,
                                           'i_clamp_min': -10.0, 'i_clamp_max': 10.0}},
}



def robot_parts(root):
    """The links and joints as comparable text: what decides the physics."""
    parts = [e for e in root if e.tag in ('link', 'joint')]
    for part in parts:
        part.tail = None  # the whitespace after an element is the file's layout, not the robot
    return [ET.tostring(e) for e in parts]


def test_urdf_variant_is_the_tutorial_robot_plus_transmission_and_plugin_tag():
    variant, tutorial = ET.parse(JNT_CTL_URDF).getroot(), ET.parse(TUTORIAL_URDF).getroot()
    assert variant.get('name') == tutorial.get('name') == ROBOT
    assert robot_parts(variant) == robot_parts(tutorial)
    transmission, = variant.findall('transmission')
    assert transmission.findtext('type') == 'transmission_interface/SimpleTransmission'
    joint, = transmission.findall('joint')
    assert joint.get('name') == 'joint1'
    assert joint.findtext('hardwareInterface') == 'EffortJointInterface'
    assert transmission.find('actuator').findtext('mechanicalReduction') == '1'
    plugin, = variant.findall('gazebo/plugin')
    assert (plugin.get('name'), plugin.get('filename')) == (
        'gazebo_ros_control', 'libgazebo_ros_control.so')
    assert plugin.findtext('robotNamespace') == NS


def test_yaml_is_the_books():
    with open(BOOK_YAML) as f:
        assert yaml.safe_load(f) == {NS.strip('/'): BOOK_PARAMS}


def launch_spawns_robot_and_controllers(ros, rospy_client, launch, expected_nodes, update_rate):
    """Runs `launch`; checks its nodes, the robot and controllers it starts (the world at
    `update_rate` steps per wall second), and that the link then holds the book's command."""
    nodes = ros.run(launch[:1] + ['--nodes'] + launch[1:])
    assert sorted(nodes.stdout.split()) == sorted(expected_nodes), nodes
    ros.start(launch, name='roslaunch')
    api = GazeboApi(rospy_client)
    ros.wait_until(lambda: ros.has_service('/gazebo/get_model_state')
                   and api.get_model_state(ROBOT, '').success, 60, what=ROBOT + ' spawned')
    assert api.get_physics_properties().max_update_rate == update_rate
    wait_for_listing(ros, rospy_client, BOOK_CONTROLLERS_RUNNING, 'both controllers running')
    assert rospy_client.get_param(NS + '/joint1_position_controller/pid') == (
        BOOK_PARAMS['joint1_position_controller']['pid'])
    with open(JNT_CTL_URDF) as f:
        assert rospy_client.get_param('/robot_description') == f.read()
    # As the student commands it; the integral term takes the droop away.
    command_topic = NS + '/joint1_position_controller/command'
    ros.start(['rostopic', 'pub', command_topic, 'std_msgs/Float64', '1.0'], name='rostopic_pub')

    def published():
        _, _, (publishers, _, _) = ros.master().getSystemState('/test')
        return any(topic == command_topic for topic, _ in publishers)
    ros.wait_until(published, 60, what='rostopic pub on ' + command_topic)
    # The settling's sim time in a few wall seconds: the world runs flat out from the command on
    # (a world flat out from its start would spend a core on every wall second the launch takes).
    api.set_physics(max_update_rate=0)

    def holding():
        position, rate = api.joint()
        return abs(position - 1.0) < 1e-3 and abs(rate) < 1e-3
    wait_until(holding, 120, what='the link to hold 1.0 rad')


def test_book_launch_runs_as_printed(ros, rospy_client):
    """The launch file starts the simulator itself (its empty_world.launch include), at Gazebo's
    default pace."""
    launch_spawns_robot_and_controllers(
        ros, rospy_client,
        ['roslaunch', 'minimal_robot_description', 'minimal_robot_w_jnt_ctl.launch'],
        ['/gazebo', '/gazebo_gui', NS + '/controller_spawner', '/spawn_urdf'], 1000)


def test_our_launch_starts_the_simulator_too(ros, rospy_client):
    launch_spawns_robot_and_controllers(
        ros, rospy_client,
        ['roslaunch', 'minimal_robot_description', 'minimal_robot_in_sim_w_jnt_ctl.launch',
         'max_update_rate:=100'],
        ['/gazebo', NS + '/controller_spawner', '/spawn_one_DOF_robot'], 100)
