"""The tutorial robot's URDF: parsed by urdfdom, and exactly the robot of shared/docs/tutorial.md."""
import subprocess
import xml.etree.ElementTree as ET

import pytest

from conftest import TUTORIAL_URDF


def test_check_urdf_parses_the_robot():
    result = subprocess.run(['check_urdf', TUTORIAL_URDF], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "robot name is: one_DOF_robot" in result.stdout
    assert 'root Link: world has 1 child(ren)' in result.stdout
    assert 'child(1):  link1' in result.stdout
    assert 'child(1):  link2' in result.stdout


def floats(text):
    return [float(v) for v in text.split()]


@pytest.fixture(scope='module')
def robot():
    return ET.parse(TUTORIAL_URDF).getroot()


def link(robot, name):
    return robot.find("link[@name='%s']" % name)


def test_fixed_joint_glues_link1_to_world(robot):
    joint = robot.find("joint[@name='glue_robot_to_world']")
    assert joint.get('type') == 'fixed'
    assert joint.find('parent').get('link') == 'world'
    assert joint.find('child').get('link') == 'link1'


def test_joint1_is_continuous_about_y_at_z1(robot):
    joint = robot.find("joint[@name='joint1']")
    assert joint.get('type') == 'continuous'
    assert joint.find('parent').get('link') == 'link1'
    assert joint.find('child').get('link') == 'link2'
    assert floats(joint.find('origin').get('xyz')) == [0, 0, 1.0]
    assert floats(joint.find('axis').get('xyz')) == [0, 1, 0]
    assert joint.find('limit') is None and joint.find('dynamics') is None


@pytest.mark.parametrize('name,inertia', [
    ('link1', dict(ixx=1, ixy=0, ixz=0, iyy=1, iyz=0, izz=1)),
    ('link2', dict(ixx=0.1, ixy=0, ixz=0, iyy=0.1, iyz=0, izz=0.005)),
])
def test_inertials(robot, name, inertia):
    inertial = link(robot, name).find('inertial')
    assert floats(inertial.find('origin').get('xyz')) == [0, 0, 0.5]
    assert floats(inertial.find('origin').get('rpy')) == [0, 0, 0]
    assert float(inertial.find('mass').get('value')) == 1.0
    assert {k: float(v) for k, v in inertial.find('inertia').attrib.items()} == inertia


def test_link1_visual_and_shorter_collision_boxes(robot):
    link1 = link(robot, 'link1')
    visual, collision = link1.find('visual'), link1.find('collision')
    assert floats(visual.find('geometry/box').get('size')) == [0.2, 0.2, 1.0]
    assert floats(collision.find('geometry/box').get('size')) == [0.2, 0.2, 0.7]
    for element in (visual, collision):
        assert floats(element.find('origin').get('xyz')) == [0, 0, 0.5]


def test_link2_cylinders(robot):
    link2 = link(robot, 'link2')
    for element in (link2.find('visual'), link2.find('collision')):
        cylinder = element.find('geometry/cylinder')
        assert (float(cylinder.get('length')), float(cylinder.get('radius'))) == (1.0, 0.1)
        assert floats(element.find('origin').get('xyz')) == [0, 0, 0.5]
