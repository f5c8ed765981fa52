"""The book's gazebo_ros names, driven as the book types them against the real simulator node:
gzserver / gazebo / gzclient, spawn_model, empty_world.launch included by a launch file of the
book's shape, the gazebo_ros.gazebo_interface module, and gzserver-side model:// resolution of the
request gazebo_ros' spawn_model sends for -database."""
import os

import pytest

from api_client import ROBOT, GazeboApi, pose
from conftest import ENGINES, GROUND, TUTORIAL_URDF, WORKSPACE
from gazebo_commands import output, run, start_serving
from onedof_harness.private_ros import wait_until

STANDIN = "this workspace's simulator, standing in for Gazebo"
NO_GUI = 'no Gazebo GUI in this workspace; instead rviz shows the simulated world'
HEADLESS = {'DISPLAY': ''}
# What gazebo_ros' spawn_model sends for `-database cafe_table` (its MODEL_DATABASE_TEMPLATE).
DATABASE_REQUEST = ('<sdf version="1.4">\n    <world name="default">\n        <include>\n'
                    '            <uri>model://{}</uri>\n        </include>\n    </world>\n</sdf>')
BOX_HALF_SIDE = 0.1  # api_client's BOX_SDF
# An ASCII STL spanning x, y in [-0.1, 0.1], z in [0, 0.3].
def box_stl(x0, y0, z0, x1, y1, z1):
    """An ASCII STL of the closed box between two corners, its triangles wound outwards."""
    corners = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    lines = ['solid block']
    for a, b, c, d in faces:
        for triangle in ((a, b, c), (a, c, d)):
            lines += ['facet normal 0 0 0', 'outer loop']
            lines += ['vertex %g %g %g' % corners[i] for i in triangle]
            lines += ['endloop', 'endfacet']
    return '\n'.join(lines + ['endsolid block']) + '\n'


BLOCK_STL = box_stl(-0.1, -0.1, 0, 0.1, 0.1, 0.3)


def write_model(folder, name, link_content):
    model = folder / name
    (model / 'meshes').mkdir(parents=True)
    (model / 'model.config').write_text(
        '<model><name>%s</name><sdf version="1.6">model.sdf</sdf></model>' % name)
    (model / 'model.sdf').write_text(
        '<sdf version="1.6"><model name="%s"><static>true</static><link name="link">%s</link>'
        '</model></sdf>' % (name, link_content))
    return model


# --- gzserver, gazebo, gzclient ---------------------------------------------------------------

@pytest.mark.parametrize('engine', ENGINES)
def test_gzserver_runs_the_simulator_with_gzservers_arguments(ros, rospy_client, engine):
    server = start_serving(ros, ['rosrun', 'gazebo_ros', 'gzserver', '-u', '-e', engine,
                                 'worlds/empty.world'], 'gzserver')
    physics = GazeboApi(rospy_client).get_physics_properties()
    assert physics.pause, 'gzserver -u starts paused'
    assert '(engine: %s)' % engine in physics.status_message
    log = ros.log_text(server)
    assert log.splitlines()[0].startswith('gzserver: onedof_sim, ' + STANDIN), log
    # Gazebo's default world is this package's: the ground plane, the sun, the node's physics.
    assert "world 'default' from %s/src/onedof_sim/worlds/empty.world: 1 model" % WORKSPACE in log
    assert 'ignoring command-line argument' not in log, log
    assert GazeboApi(rospy_client).get_world_properties().model_names == [GROUND]


def test_gzserver_help_says_what_stands_in(ros):
    result = run(ros, 'rosrun', 'gazebo_ros', 'gzserver', '-h')
    assert result.returncode == 0, output(result)
    assert STANDIN in result.stdout and '-e ENGINE' in result.stdout


def test_gzclient_without_a_display_says_what_instead_in_one_line_and_exits_0(ros):
    result = run(ros, 'rosrun', 'gazebo_ros', 'gzclient', env=HEADLESS)
    assert result.returncode == 0, output(result)
    assert result.stdout.count('\n') == 1, output(result)
    assert result.stdout.startswith('gzclient: ' + NO_GUI), output(result)
    assert 'not started, there is no display' in result.stdout


def test_gazebo_without_a_display_keeps_only_the_server(ros, rospy_client):
    gazebo = start_serving(ros, ['rosrun', 'gazebo_ros', 'gazebo', '-u'], 'gazebo', env=HEADLESS)
    assert GazeboApi(rospy_client).get_physics_properties().pause
    first = ros.log_text(gazebo).splitlines()[0]
    assert first.startswith('gazebo: onedof_sim, ' + STANDIN), first
    assert NO_GUI in first and 'not started' in first
    ros.terminate(gazebo)
    assert gazebo.returncode is not None


# --- spawn_model and model:// -------------------------------------------------------------------

def test_spawn_model_is_the_onedof_sim_program(ros):
    ours = run(ros, 'rosrun', 'gazebo_ros', 'spawn_model', '-h')
    theirs = run(ros, 'rosrun', 'onedof_sim', 'spawn_model', '-h')
    assert ours.returncode == 0 and ours.stdout == theirs.stdout, output(ours)
    assert 'standing in for Gazebo' in ' '.join(ours.stdout.split())


def test_books_table_command_through_gazebo_ros(ros, rospy_client, running_sim):
    result = run(ros, 'rosrun', 'gazebo_ros', 'spawn_model', '-database', 'cafe_table', '-sdf',
                 '-model', 'cafe_table', '-x', '0.85')
    assert result.returncode == 0, output(result)
    assert 'standing in for Gazebo' in result.stdout.splitlines()[0]
    state = GazeboApi(rospy_client).get_model_state('cafe_table', '')
    assert state.success and state.pose.position.x == pytest.approx(0.85)


def test_gazebo_ros_database_request_resolves_in_the_server(ros, rospy_client, engine, tmp_path):
    """The request gazebo_ros' spawn_model builds for -database cafe_table -sdf -model cafe_table
    -x 0.85, sent as it sends it; models also come from the server's GAZEBO_MODEL_PATH, with
    their mesh collisions."""
    write_model(tmp_path, 'stl_block',
                '<collision name="hull"><geometry><mesh><uri>model://stl_block/meshes/block.stl'
                '</uri></mesh></geometry></collision><visual name="look"><geometry><mesh><uri>'
                'model://stl_block/meshes/block.dae</uri></mesh></geometry></visual>')
    (tmp_path / 'stl_block' / 'meshes' / 'block.stl').write_text(BLOCK_STL)
    start_serving(ros, ['rosrun', 'onedof_sim', 'onedof_sim', '_physics:=' + engine], 'sim',
                  env={'GAZEBO_MODEL_PATH': str(tmp_path)})
    api = GazeboApi(rospy_client)

    table = api.spawn_sdf_model('cafe_table', DATABASE_REQUEST.format('cafe_table'), '/',
                                pose(x=0.85), '')
    assert table.success, table.status_message
    properties = api.get_model_properties('cafe_table')
    assert properties.is_static and properties.geom_names == ['surface', 'column', 'base']
    assert api.get_model_state('cafe_table', '').pose.position.x == pytest.approx(0.85)

    block = api.spawn_sdf_model('block', DATABASE_REQUEST.format('stl_block'), '/',
                                pose(x=-1), '')
    assert block.success, block.status_message
    # A box resting on the block's top (z 0.3) shows that the model's mesh collides.
    api.spawn_box('box', pose(x=-1, z=0.5))
    api.run_for(1500 * 10 ** 6)
    box_bottom = api.get_model_state('box', '').pose.position.z - BOX_HALF_SIDE
    assert box_bottom == pytest.approx(0.3, abs=0.005)

    missing = api.spawn_sdf_model('chair', DATABASE_REQUEST.format('chair'), '/', pose(), '')
    assert not missing.success
    assert 'model://chair is not in the model path' in missing.status_message
    assert str(tmp_path) in missing.status_message


# --- launch files and gazebo_interface ------------------------------------------------------------

def test_empty_world_launch_takes_gazebos_arguments(ros, rospy_client):
    launch = ['roslaunch', 'gazebo_ros', 'empty_world.launch', 'paused:=true',
              'use_sim_time:=true', 'gui:=true', 'headless:=false', 'recording:=false',
              'debug:=false', 'physics:=' + ENGINES[-1], 'verbose:=true',
              'world_name:=worlds/empty.world', 'respawn_gazebo:=false', 'extra_gazebo_args:=',
              'output:=screen', 'server_required:=false', 'gui_required:=false',
              'enable_ros_network:=true', 'use_clock_frequency:=true', 'pub_clock_frequency:=100']
    roslaunch = start_serving(ros, launch, 'roslaunch', env=HEADLESS)
    physics = GazeboApi(rospy_client).get_physics_properties()
    assert physics.pause and '(engine: %s)' % ENGINES[-1] in physics.status_message
    assert rospy_client.get_param('/gazebo/pub_clock_frequency') == 100
    wait_until(lambda: 'not started, there is no display' in ros.log_text(roslaunch), 30,
               what='gzclient to say that there is no display')
    assert NO_GUI in ros.log_text(roslaunch)


BOOK_LAUNCH = """<launch>
  <include file="$(find gazebo_ros)/launch/empty_world.launch">
    <arg name="paused" value="false"/>
    <arg name="gui" value="false"/>
  </include>
  <param name="robot_description" textfile="{urdf}"/>
  <node name="spawn_robot" pkg="gazebo_ros" type="spawn_model"
        args="-param robot_description -urdf -model {robot}"/>
  <node name="spawn_table" pkg="gazebo_ros" type="spawn_model"
        args="-database cafe_table -sdf -model cafe_table -x 0.85"/>
</launch>
"""


def test_books_launch_file_shape_works(ros, rospy_client, tmp_path):
    launch_file = tmp_path / 'book.launch'
    launch_file.write_text(BOOK_LAUNCH.format(urdf=TUTORIAL_URDF, robot=ROBOT))
    roslaunch = ros.start(['roslaunch', str(launch_file)], name='roslaunch')
    api = GazeboApi(rospy_client)
    wait_until(lambda: roslaunch.poll() is not None or
               set(api.get_world_properties().model_names) == {GROUND, ROBOT, 'cafe_table'}, 60,
               what='the robot and the table to be spawned')
    assert roslaunch.poll() is None, ros.log_text(roslaunch)


def test_gazebo_interface_calls_the_simulator(ros, rospy_client, shared_sim):
    from gazebo_ros import gazebo_interface
    with open(TUTORIAL_URDF) as f:
        urdf = f.read()
    assert gazebo_interface.spawn_urdf_model_client(ROBOT, urdf, '/', pose(), '', '/gazebo')
    assert not gazebo_interface.spawn_urdf_model_client(ROBOT, urdf, '/', pose(), '', '/gazebo')
    # Paused: the joint keeps the angle set however late it is read (running, the link falls
    # from it at once, and a busy machine reads it tenths of a radian later).
    assert gazebo_interface.set_model_configuration_client(ROBOT, '', ['joint1'], [0.5],
                                                           '/gazebo')
    assert shared_sim.get_joint_properties('joint1').position[0] == pytest.approx(0.5, abs=1e-9)
    assert gazebo_interface.spawn_sdf_model_client(
        'cafe_table', DATABASE_REQUEST.format('cafe_table'), '/', pose(x=0.85), '', '/gazebo')


def test_books_paused_world_then_robot_from_the_parameter_at_an_angle_then_unpaused(
        ros, rospy_client, engine):
    """The book's Part 2, as typed: the paused empty world, the robot spawned from
    robot_description with joint1 at 1.0 rad, physics unpaused by spawn_model itself."""
    start_serving(ros, ['roslaunch', 'gazebo_ros', 'empty_world.launch', 'paused:=true',
                        'gui:=false', 'physics:=' + engine], 'roslaunch', env=HEADLESS)
    with open(TUTORIAL_URDF) as urdf:
        ros.set_param('/robot_description', urdf.read())
    api = GazeboApi(rospy_client)
    assert api.get_physics_properties().pause
    result = run(ros, 'rosrun', 'gazebo_ros', 'spawn_model', '-param', 'robot_description',
                 '-urdf', '-model', ROBOT, '-J', 'joint1', '1.0', '-unpause')
    assert result.returncode == 0, output(result)
    assert 'SetModelConfiguration: success' in result.stdout, output(result)
    assert not api.get_physics_properties().pause
    # Released at rest at 1.0 rad, gravity (m g d sin q) turns the link further from upright.
    wait_until(lambda: api.joint()[0] > 1.01, 30, what='joint1 to fall on from 1.0 rad')
    assert api.get_world_properties().sim_time > 0
