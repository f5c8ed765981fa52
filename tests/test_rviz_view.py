"""What the student sees in rviz: the committed view (minimal_robot.rviz) against the markers the
simulator publishes, with the tutorial's launch file and the cafe table spawned as in the tutorial.

The world's collision geometry comes in one marker namespace per model; the view shows the
MarkerArray with the robot's namespace off (its RobotModel draws it; both at once z-fight) and every
other model (the table) on.
"""
import os
import re
import xml.etree.ElementTree as ElementTree

import yaml

from onedof_harness.private_ros import wait_until

DESCRIPTION = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'src',
                           'minimal_robot_description')
SPAWN_TABLE = ['rosrun', 'onedof_sim', 'spawn_model', '-database', 'cafe_table', '-sdf',
               '-model', 'cafe_table', '-x', '0.85']


def collision_display():
    with open(os.path.join(DESCRIPTION, 'rviz', 'minimal_robot.rviz')) as f:
        config = yaml.safe_load(f)
    displays = [d for d in config['Visualization Manager']['Displays']
                if d.get('Marker Topic') == '/gazebo/collision_markers']
    assert len(displays) == 1, 'one MarkerArray display on /gazebo/collision_markers'
    return displays[0]


def display_launch_params():
    """The parameters display.launch (the view's launch file) sets, {name: value}."""
    root = ElementTree.parse(os.path.join(DESCRIPTION, 'launch', 'display.launch')).getroot()
    return {p.get('name'): p.get('value') for p in root.findall('param')}


def launched_robot_name():
    with open(os.path.join(DESCRIPTION, 'launch', 'minimal_robot_description.launch')) as f:
        return re.search(r'-model (\S+)"', f.read()).group(1)


def shown(display, namespace):
    """Whether rviz draws a namespace: listed ones as configured, new ones on (rviz's default)."""
    return display['Enabled'] and (display.get('Namespaces') or {}).get(namespace, True)


def test_rviz_shows_the_table_and_not_the_robots_own_collision_geometry(ros, rospy_client):
    ros.start(['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch'],
              name='launch')
    from gazebo_msgs.srv import GetModelState
    from visualization_msgs.msg import Marker, MarkerArray
    rospy_client.wait_for_service('/gazebo/get_model_state', timeout=60)
    robot = launched_robot_name()
    model_state = rospy_client.ServiceProxy('/gazebo/get_model_state', GetModelState)
    wait_until(lambda: model_state(robot, '').success, 60, what='%s to be spawned' % robot)
    # The simulator publishes its markers when asked, as the view's launch file asks, here while
    # it runs.
    asked = display_launch_params()
    assert asked.get('/gazebo/enable_collision_markers') == 'true'
    rospy_client.set_param('/gazebo/enable_collision_markers', True)
    result = ros.run(SPAWN_TABLE)
    assert result.returncode == 0, result.stdout + result.stderr

    def namespaces_with_the_table():
        msg = rospy_client.wait_for_message('/gazebo/collision_markers', MarkerArray, timeout=30)
        namespaces = {m.ns for m in msg.markers if m.action == Marker.ADD}
        return namespaces if 'cafe_table' in namespaces else None
    drawn = wait_until(namespaces_with_the_table, 30, what='the table among the collision markers')

    # One namespace per model, named as the model: a checkbox per model in rviz.
    assert robot in drawn and 'cafe_table' in drawn
    assert all('::' not in ns for ns in drawn)
    display = collision_display()
    assert not shown(display, robot), 'the robot z-fights its own visuals'
    assert [ns for ns in drawn if ns != robot and not shown(display, ns)] == []

