"""xacro's limits (src/xacro/src/xacro_ros1/limits.py) over the real command, as users type it
(`rosrun xacro xacro FILE`) and as launch files run it (`$(find xacro)/xacro` in a <param
command=>, read by roslaunch): a careless file (a macro that calls itself, one that doubles itself
30 times, a file that includes itself, a 1 GB include, a FIFO, a value past memory) ends with an
error naming the limit, in bounded memory; a robot of the book's Baxter's size still converts."""
import os
import resource
import xml.etree.ElementTree as ET

import pytest
import yaml

from test_xacro import run, xacro_env  # noqa: F401 (a fixture)

HEADER = '<?xml version="1.0"?>\n<robot name="careless" xmlns:xacro="http://www.ros.org/wiki/xacro">'
# Far above any conversion's need, and far below what an unbounded one reaches (many GB).
CHILDREN_RSS_BOUND_KB = 1024 * 1024


def careless_files(folder):
    """Each case: its file and the words of its error."""
    (folder / 'huge.xml').touch()
    os.truncate(str(folder / 'huge.xml'), 2 ** 30)  # sparse: 1 GB read, no disk taken
    os.mkfifo(str(folder / 'pipe.xml'))
    leaves = '<a/>' * 64
    cases = {
        'macro calling itself': (
            '<xacro:macro name="again"><link name="l"/><xacro:again/><xacro:again/></xacro:macro>'
            '<xacro:again/>', 'macro calls nested deeper than the limit of 100'),
        'macro doubling itself 30 times': (
            '<xacro:macro name="twice" params="n">'
            '<xacro:if value="${n > 0}"><xacro:twice n="${n-1}"/><xacro:twice n="${n-1}"/>'
            '</xacro:if><xacro:if value="${n == 0}">%s</xacro:if></xacro:macro>'
            '<xacro:twice n="30"/>' % leaves, 'more elements than the limit of 100000'),
        'file including itself': (
            '<xacro:include filename="file_including_itself.xacro"/>',
            'includes nested deeper than the limit of 100'),
        '1 GB include': (
            '<xacro:include filename="huge.xml"/>',
            'the file has 1073741824 bytes, past the limit of 16 MiB (16777216 bytes) xacro '
            'reads from one file'),
        'FIFO include': (
            '<xacro:include filename="pipe.xml"/>',
            'it is a FIFO, not a regular file: xacro reads regular files only'),
        '32 Mi characters value': (
            '<link name="${\'x\' * 2**25}"/>',
            'a value of 33554432 characters, past the limit of 16777216'),
        '8 GB value': (
            '<link name="${\'x\' * 2**33}"/>', 'out of memory at the limit of 4 GiB'),
    }
    files = {}
    for name, (body, message) in cases.items():
        path = folder / (name.replace(' ', '_') + '.xacro')
        path.write_text(HEADER + body + '</robot>\n')
        files[name] = (str(path), message)
    return files


CASES = ['macro calling itself', 'macro doubling itself 30 times', 'file including itself',
         '1 GB include', 'FIFO include', '32 Mi characters value', '8 GB value']


def launch_file(folder, xacro_file):
    launch = folder / 'robot.launch'
    launch.write_text('<launch>\n  <param name="robot_description" '
                      'command="$(find xacro)/xacro \'%s\'"/>\n</launch>\n' % xacro_file)
    return str(launch)


def children_peak_rss_kb():
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss


@pytest.mark.parametrize('case', CASES)
def test_a_careless_file_ends_with_the_limit_named(xacro_env, tmp_path, case):  # noqa: F811
    xacro_file, message = careless_files(tmp_path)[case]
    result = run(['rosrun', 'xacro', 'xacro', xacro_file], xacro_env, timeout=900)
    assert result.returncode == 2, result.stderr[-2000:]
    assert message in result.stderr, result.stderr[-2000:]
    assert result.stdout == ''
    # As a launch file runs it: roslaunch reads the command's output into the parameter
    # (--dump-params: loading the launch file is all, and the parameter is not there).
    launched = run(['roslaunch', '--dump-params', launch_file(tmp_path, xacro_file)], xacro_env,
                   timeout=900)
    output = launched.stdout + launched.stderr
    assert 'robot_description' not in launched.stdout, output[-2000:]
    assert message in output, output[-2000:]
    assert 'Cannot load command parameter [robot_description]' in output, output[-2000:]
    assert children_peak_rss_kb() < CHILDREN_RSS_BOUND_KB


ARM_LINKS = 14  # per arm: 7 moving joints, each with a link and a fixed flange link after it


def book_size_robot(folder):
    """A two-armed robot of the book's Baxter's size (about 700 elements once converted), written
    as such robots are: its macros in an included file, nested three deep, properties, math and
    $(arg)."""
    (folder / 'parts.xacro').write_text('''<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="radius" value="0.04"/>
  <xacro:macro name="cylinder_inertial" params="mass length">
    <inertial>
      <origin xyz="0 0 ${length / 2}" rpy="0 0 0"/>
      <mass value="${mass}"/>
      <inertia ixx="${mass * (3 * radius**2 + length**2) / 12}" ixy="0" ixz="0"
               iyy="${mass * (3 * radius**2 + length**2) / 12}" iyz="0"
               izz="${mass * radius**2 / 2}"/>
    </inertial>
  </xacro:macro>
  <xacro:macro name="arm_link" params="name length mass">
    <link name="${name}">
      <xacro:cylinder_inertial mass="${mass}" length="${length}"/>
      <visual>
        <origin xyz="0 0 ${length / 2}" rpy="0 0 0"/>
        <geometry><cylinder radius="${radius}" length="${length}"/></geometry>
        <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
      </visual>
      <collision>
        <origin xyz="0 0 ${length / 2}" rpy="0 0 0"/>
        <geometry><cylinder radius="${radius}" length="${length}"/></geometry>
      </collision>
    </link>
    <gazebo reference="${name}"><material>Gazebo/Grey</material><mu1>0.8</mu1><mu2>0.8</mu2></gazebo>
  </xacro:macro>
  <xacro:macro name="arm_joint" params="name type parent child z">
    <joint name="${name}" type="${type}">
      <parent link="${parent}"/>
      <child link="${child}"/>
      <origin xyz="0 0 ${z}" rpy="0 0 0"/>
      <axis xyz="0 0 1"/>
      <limit lower="${-pi / 2}" upper="${pi / 2}" effort="50" velocity="2"/>
      <dynamics damping="0.7"/>
    </joint>
  </xacro:macro>
  <xacro:macro name="arm" params="side y">
    <joint name="${side}_mount" type="fixed">
      <parent link="torso"/><child link="${side}_0"/><origin xyz="0 ${y} 0.6" rpy="0 0 0"/>
    </joint>
''' + ''.join('''    <xacro:arm_link name="${side}_%d" length="0.2" mass="%s"/>
''' % (i, 3.0 - 0.2 * i) for i in range(ARM_LINKS)) + ''.join('''    <xacro:arm_joint name="${side}_j%d" type="%s" parent="${side}_%d" child="${side}_%d" z="0.2"/>
''' % (i, 'revolute' if i % 2 == 1 else 'fixed', i - 1, i) for i in range(1, ARM_LINKS)) + '''  </xacro:macro>
</robot>
''')
    robot = folder / 'two_arms.xacro'
    robot.write_text('''<?xml version="1.0"?>
<robot name="two_arms" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="torso_mass" default="20"/>
  <xacro:include filename="parts.xacro"/>
  <link name="torso">
    <xacro:cylinder_inertial mass="$(arg torso_mass)" length="0.6"/>
  </link>
  <xacro:arm side="left" y="0.25"/>
  <xacro:arm side="right" y="-0.25"/>
</robot>
''')
    return str(robot)


def check_two_arms(urdf_text):
    robot = ET.fromstring(urdf_text)
    assert robot.get('name') == 'two_arms'
    assert float(robot.find("link[@name='torso']/inertial/mass").get('value')) == 20
    links = [link.get('name') for link in robot.iter('link') if link.get('name')]
    assert links == ['torso'] + ['%s_%d' % (side, i) for side in ('left', 'right')
                                 for i in range(ARM_LINKS)]
    joints = robot.findall('joint')
    assert len(joints) == 2 * ARM_LINKS
    assert sum(1 for joint in joints if joint.get('type') == 'revolute') == 2 * (ARM_LINKS // 2)
    elements = sum(1 for _ in robot.iter())
    assert 650 <= elements <= 1000, elements  # the size the case stands for


def test_a_book_size_robot_still_converts(xacro_env, tmp_path):  # noqa: F811
    robot = book_size_robot(tmp_path)
    result = run(['rosrun', 'xacro', 'xacro', robot], xacro_env, timeout=900)
    assert result.returncode == 0, result.stderr
    check_two_arms(result.stdout)
    urdf = tmp_path / 'two_arms.urdf'
    urdf.write_text(result.stdout)
    check = run(['check_urdf', str(urdf)], xacro_env)
    assert check.returncode == 0, check.stdout + check.stderr
    launched = run(['roslaunch', '--dump-params', launch_file(tmp_path, robot)], xacro_env,
                   timeout=900)
    assert launched.returncode == 0, launched.stdout + launched.stderr
    check_two_arms(yaml.safe_load(launched.stdout)['/robot_description'])
