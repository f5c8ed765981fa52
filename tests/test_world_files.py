"""World files, as Gazebo users start them: `roslaunch gazebo_ros empty_world.launch
world_name:=FILE`, `rosrun gazebo_ros gazebo FILE` and gzserver. The world's physics and gravity,
its models and its includes of model://NAME (this package's models/ and GAZEBO_MODEL_PATH) with
<name>, <pose> and <static> over the included model's; lights accepted and said once; scene said
to be not simulated, a world plugin logged as Gazebo logs one it cannot load; a world that cannot
be loaded ends the simulator naming why. Worlds are read as Gazebo reads them: a world saved by
Gazebo 11 and worlds in the shapes of gazebo_ros_pkgs' test worlds (tests/worlds/) load, with the
warnings Gazebo gives and the errors it logs for plugins and meshes it cannot load."""
import math
import os

import pytest

from api_client import GazeboApi
from conftest import ENGINES, WORKSPACE
from gazebo_commands import output, run, start_serving

HEADLESS = {'DISPLAY': ''}
TABLE_TOP = 0.775      # cafe_table: the top face of its surface box
BLOCK_HALF = 0.0175    # toy_block: 0.035 m high
BEER_HALF = 0.115      # beer: 0.23 m long
TABLE_X, TABLE_Y, TABLE_YAW = 1.2, -0.4, 0.5

# A world of our own making with what the book's worlds use: includes of ground_plane, sun and
# cafe_table (its pose overridden), a toy_block and a beer (renamed) dropped on the table from a
# few centimetres, a toy_block made static in the air, and physics unlike the defaults.
CAFE_WORLD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="test_cafe">
    <include><uri>model://ground_plane</uri></include>
    <include><uri>model://sun</uri></include>
    <include>
      <uri>model://cafe_table</uri>
      <pose>{x} {y} 0 0 0 {yaw}</pose>
    </include>
    <include>
      <uri>model://toy_block</uri>
      <pose>{x} {y} 0.82 0 0 0</pose>
    </include>
    <include>
      <uri>model://beer</uri>
      <name>my_beer</name>
      <pose>{beer_x} {y} 0.92 0 0 0</pose>
    </include>
    <include>
      <uri>model://toy_block</uri>
      <name>floating_block</name>
      <static>true</static>
      <pose>-1 0 0.5 0 0 0</pose>
    </include>
    <gravity>0 0 -9</gravity>
    <physics type="{engine}">
      <max_step_size>0.002</max_step_size>
      <real_time_update_rate>0</real_time_update_rate>
    </physics>
  </world>
</sdf>
"""
CAFE_MODELS = ['ground_plane', 'cafe_table', 'toy_block', 'my_beer', 'floating_block']

# The shape of the book's play_pen.world and cafe.world: SDF 1.4, gravity inside <physics>.
BOOK_SHAPED_WORLD = """<?xml version="1.0" ?>
<sdf version="1.4">
  <world name="default">
    <include>
      <uri>model://ground_plane</uri>
    </include>
    <include>
      <uri>model://sun</uri>
    </include>
    <include>
        <uri>model://cafe_table</uri>
        <pose>0.8 -0.3 0 0 -0 0</pose>
    </include>
    <include>
        <uri>model://beer</uri>
         <pose>0.7 0 0.775 0 0 0</pose>
    </include>
     <include>
        <uri>model://starting_pen</uri>
         <pose>0.0 -5 0 0 0 0</pose>
    </include>
    <physics type="ode">
      <real_time_update_rate>1000.0</real_time_update_rate>
      <gravity>
        0.0 0.0 -9.81
      </gravity>
    </physics>
  </world>
</sdf>
"""


def cafe_world(folder, engine):
    path = folder / 'cafe.world'
    path.write_text(CAFE_WORLD.format(x=TABLE_X, y=TABLE_Y, yaw=TABLE_YAW, beer_x=TABLE_X + 0.2,
                                      engine=engine))
    return path


def model_position(api, name):
    state = api.get_model_state(name, '')
    assert state.success, state.status_message
    return state.pose.position


def check_cafe_world(api, engine):
    """The cafe world as loaded: its models, its physics, and the objects resting on the table."""
    world = api.get_world_properties()
    assert world.model_names == CAFE_MODELS, world
    physics = api.get_physics_properties()
    assert physics.time_step == 0.002
    assert (physics.gravity.x, physics.gravity.y, physics.gravity.z) == (0, 0, -9)
    assert physics.max_update_rate == 0
    assert '(engine: %s)' % engine in physics.status_message

    table = api.get_model_state('cafe_table', '').pose
    assert (table.position.x, table.position.y, table.position.z) == \
        pytest.approx((TABLE_X, TABLE_Y, 0), abs=1e-9)
    assert 2 * table.orientation.z * table.orientation.w == pytest.approx(math.sin(TABLE_YAW),
                                                                         abs=1e-9)
    assert api.get_model_properties('cafe_table').is_static
    assert not api.get_model_properties('toy_block').is_static
    assert api.get_model_properties('floating_block').is_static

    api.run_for(2 * 10 ** 9)  # 2 s of sim time: the block and the can fall a few cm and settle
    block = model_position(api, 'toy_block')
    assert block.z == pytest.approx(TABLE_TOP + BLOCK_HALF, abs=0.003)
    assert (block.x, block.y) == pytest.approx((TABLE_X, TABLE_Y), abs=0.002)
    beer = model_position(api, 'my_beer')
    assert beer.z == pytest.approx(TABLE_TOP + BEER_HALF, abs=0.003)
    assert (beer.x, beer.y) == pytest.approx((TABLE_X + 0.2, TABLE_Y), abs=0.002)
    assert model_position(api, 'floating_block').z == 0.5


@pytest.mark.parametrize('engine', ENGINES)
def test_world_file_loads_via_empty_world_launch(ros, rospy_client, engine, tmp_path):
    world = cafe_world(tmp_path, ENGINES[0] if engine != ENGINES[0] else ENGINES[-1])
    # physics:= names the engine over the world's <physics type>, as gzserver's -e does.
    roslaunch = start_serving(ros, ['roslaunch', 'gazebo_ros', 'empty_world.launch',
                                    'world_name:=%s' % world, 'physics:=' + engine,
                                    'paused:=true', 'gui:=false'], 'roslaunch')
    check_cafe_world(GazeboApi(rospy_client), engine)
    log = ros.log_text(roslaunch)
    assert "world 'test_cafe' from %s: 5 models" % world in log, log
    assert log.count("light 'sun' accepted, not simulated") == 1, log


@pytest.mark.parametrize('engine', ENGINES)
def test_world_file_loads_via_rosrun_gazebo_on_its_physics_engine(ros, rospy_client, engine,
                                                                 tmp_path):
    # No engine asked for: the world's <physics type> is the engine.
    world = cafe_world(tmp_path, engine)
    gazebo = start_serving(ros, ['rosrun', 'gazebo_ros', 'gazebo', '-u', str(world)], 'gazebo',
                           env=HEADLESS)
    check_cafe_world(GazeboApi(rospy_client), engine)
    assert 'ignoring command-line argument' not in ros.log_text(gazebo)


@pytest.mark.parametrize('engine', ENGINES)
def test_book_shaped_world_loads_with_its_gravity(ros, rospy_client, engine, tmp_path):
    world = tmp_path / 'play_pen.world'
    world.write_text(BOOK_SHAPED_WORLD)
    start_serving(ros, ['rosrun', 'gazebo_ros', 'gzserver', '-u', '-e', engine, str(world)],
                  'gzserver')
    api = GazeboApi(rospy_client)
    assert api.get_world_properties().model_names == \
        ['ground_plane', 'cafe_table', 'beer', 'starting_pen']
    physics = api.get_physics_properties()
    assert physics.gravity.z == -9.81 and physics.max_update_rate == 1000
    assert physics.time_step == 0.001  # the world does not set it: the default
    pen = model_position(api, 'starting_pen')
    assert (pen.x, pen.y, pen.z) == (0, -5, 0)


@pytest.mark.parametrize('engine', ENGINES)
def test_models_inline_and_from_gazebo_model_path_and_what_is_ignored_is_said(
        ros, rospy_client, engine, tmp_path):
    crate = tmp_path / 'models' / 'crate'
    crate.mkdir(parents=True)
    (crate / 'model.config').write_text(
        '<model><name>crate</name><sdf version="1.6">model.sdf</sdf></model>')
    (crate / 'model.sdf').write_text(
        '<sdf version="1.6"><model name="crate"><link name="link"><collision name="c">'
        '<geometry><box><size>0.4 0.4 0.4</size></box></geometry></collision></link>'
        '</model></sdf>')
    world = tmp_path / 'mixed.world'
    world.write_text(
        '<sdf version="1.6"><world name="mixed">'
        '<include><uri>model://crate</uri><pose>2 0 0.2 0 0 0</pose></include>'
        '<model name="post"><static>true</static><pose>0 3 0.5 0 0 0</pose>'
        '<link name="link"><collision name="c"><geometry><cylinder><radius>0.1</radius>'
        '<length>1</length></cylinder></geometry></collision></link></model>'
        '<light type="point" name="lamp"><pose>0 0 3 0 0 0</pose></light>'
        '<scene><ambient>0.4 0.4 0.4 1</ambient></scene>'
        '<plugin name="world_ticker" filename="libworld_ticker.so"/>'
        '</world></sdf>')
    gzserver = start_serving(ros, ['rosrun', 'gazebo_ros', 'gzserver', '-u', '-e', engine,
                                   str(world)], 'gzserver',
                             env={'GAZEBO_MODEL_PATH': str(tmp_path / 'models')})
    api = GazeboApi(rospy_client)
    assert api.get_world_properties().model_names == ['crate', 'post']
    post = model_position(api, 'post')
    assert (post.x, post.y, post.z) == (0, 3, 0.5)
    log = ros.log_text(gzserver)
    assert "world 'mixed': light 'lamp' accepted, not simulated" in log, log
    assert ("world 'mixed': Failed to load plugin libworld_ticker.so (plugin 'world_ticker')"
            in log), log
    assert "world 'mixed': not simulated: <scene>" in log, log
    # What a physics parameter is not given keeps the node's default.
    assert api.get_physics_properties().time_step == 0.001


def test_world_with_a_missing_include_stops_the_launch_naming_it(ros, tmp_path):
    world = tmp_path / 'broken.world'
    world.write_text('<sdf version="1.6"><world name="broken">'
                     '<include><uri>model://ground_plane</uri></include>'
                     '<include><uri>model://no_such_model</uri></include></world></sdf>')
    result = ros.run(['roslaunch', 'gazebo_ros', 'empty_world.launch', 'world_name:=%s' % world,
                      'gui:=false'])
    text = result.stdout + result.stderr
    assert ("world file '%s' cannot be loaded: <include> model://no_such_model is not in the "
            "model path" % world) in text, output(result)
    assert 'all processes on machine have died' in text, output(result)


REFUSED = {
    'missing_include': ('<sdf version="1.6"><world name="w">'
                        '<include><uri>model://no_such_model</uri></include></world></sdf>',
                        "cannot be loaded: <include> model://no_such_model is not in the model "
                        "path or is no readable regular file ({models}"),
    'bad_xml': ('<sdf version="1.6"><world name="w"><model name="a"></world></sdf>',
                'cannot be loaded: not well-formed XML: '),
    'no_world': ('<sdf version="1.6"><model name="a"><link name="l"/></model></sdf>',
                 'cannot be loaded: the file has a <model>, no <world>'),
    'negative_count': ('<sdf version="1.6"><world name="w"><physics type="ode"><ode><solver>'
                       '<iters>-3</iters></solver></ode></physics></world></sdf>',
                       'cannot be loaded: <physics>: <iters> is a count and must be >= 0'),
    'step_out_of_range': ('<sdf version="1.6"><world name="w"><physics type="ode">'
                          '<max_step_size>0</max_step_size></physics></world></sdf>',
                          "time_step must be in [1e-06, 0.1] s (the world file's <physics>"),
    'model_refused': ('<sdf version="1.6"><world name="w"><model name="heavy"><link name="l">'
                      '<inertial><mass>1e9</mass></inertial></link></model></world></sdf>',
                      "world 'w': model 'heavy' cannot be spawned: SpawnModel: link 'l' has a "
                      "mass of 1e+09 kg"),
    'update_rate_too_large': ('<sdf version="1.6"><world name="w"><physics type="ode">'
                              '<real_time_update_rate>1e308</real_time_update_rate></physics>'
                              '</world></sdf>',
                              "the world file's <real_time_update_rate>: max_update_rate must be 0 "
                              "(as fast as possible) or between 1 and 1e+06 steps per wall second"),
    'gazebo_1_format': ('<gazebo version="1.0"><world name="w"/></gazebo>',
                        'cannot be loaded: its root element is <gazebo version="1.0">, Gazebo 1\'s '
                        'world format from before SDF, which libsdformat (and so Gazebo 11) no '
                        'longer reads'),
}


# Refused while the file is read, before the simulator makes its world and engine.
READ_REFUSED = ('bad_xml', 'gazebo_1_format', 'missing_include', 'negative_count', 'no_world',
                'update_rate_too_large')
# Refused by the world of the engine asked for: its physics, a model's spawn.
WORLD_REFUSED = ('model_refused', 'step_out_of_range')


def assert_gzserver_ends_naming_why(ros, folder, case, engine_args):
    world = folder / (case + '.world')
    world.write_text(REFUSED[case][0])
    result = run(ros, 'rosrun', 'gazebo_ros', 'gzserver', *engine_args, str(world))
    assert result.returncode == 1, (case, output(result))
    models = WORKSPACE + '/src/onedof_sim/models'
    assert REFUSED[case][1].format(models=models) in result.stdout + result.stderr, \
        (case, output(result))


def test_world_that_cannot_be_read_ends_gzserver_naming_why(ros, tmp_path):
    assert sorted(READ_REFUSED + WORLD_REFUSED) == sorted(REFUSED)
    for case in READ_REFUSED:
        assert_gzserver_ends_naming_why(ros, tmp_path, case, [])


@pytest.mark.parametrize('engine', ENGINES)
def test_world_that_cannot_be_loaded_ends_gzserver_naming_why(ros, engine, tmp_path):
    for case in WORLD_REFUSED:
        assert_gzserver_ends_naming_why(ros, tmp_path, case, ['-e', engine])


def model_folder(root, name, content):
    """A model folder NAME (model.config naming model.sdf) whose model holds `content`."""
    folder = root / name
    folder.mkdir(parents=True)
    (folder / 'model.config').write_text(
        '<?xml version="1.0"?><model><name>%s</name><sdf version="1.6">model.sdf</sdf></model>'
        % name)
    (folder / 'model.sdf').write_text('<?xml version="1.0"?><sdf version="1.6"><model name="%s">'
                                      '<link name="l"/>%s</model></sdf>' % (name, content))
    return str(folder / 'model.sdf')


def include(name, as_name):
    return '<include><uri>model://%s</uri><name>%s</name></include>' % (name, as_name)


def test_world_that_is_no_file_or_includes_itself_ends_gzserver_naming_why(ros, tmp_path):
    """A folder, a FIFO (never opened: it would wait for a writer) and /dev/zero (never read: it
    never ends) are refused as what they are; includes that include themselves, directly or
    through another, are refused naming the files around the cycle, and a tree of includes 17
    deep, each including the next twice, for the 131,071 models it would place."""
    fifo = tmp_path / 'pipe.world'
    os.mkfifo(str(fifo))
    models = tmp_path / 'models'
    self_file = model_folder(models, 'self', include('self', 'again'))
    a_file = model_folder(models, 'a', include('b', 'b'))
    b_file = model_folder(models, 'b', include('a', 'a'))
    for level in range(17):
        model_folder(models, 'level%d' % level,
                     include('level%d' % (level + 1), 'x') + include('level%d' % (level + 1), 'y')
                     if level < 16 else '')
    cases = [(str(tmp_path), 'it is a directory, not a regular file'),
             (str(fifo), 'it is a FIFO, not a regular file'),
             ('/dev/zero', 'it is a character device, not a regular file')]
    for name, content, reason in (
            ('self', include('self', 's'),
             'its <include>s include themselves: %s -> %s' % (self_file, self_file)),
            ('mutual', include('a', 'a'),
             'its <include>s include themselves: %s -> %s -> %s' % (a_file, b_file, a_file)),
            ('tree', include('level0', 'tree'),
             'its <include>s, nested ones counted each time, place 131071 models; at most 1000 '
             'are accepted')):
        world = tmp_path / (name + '.world')
        world.write_text('<sdf version="1.6"><world name="w">%s</world></sdf>' % content)
        cases.append((str(world), reason))
    for path, reason in cases:
        result = run(ros, 'rosrun', 'gazebo_ros', 'gzserver', path,
                     env={'GAZEBO_MODEL_PATH': str(models)})
        assert result.returncode == 1, (path, output(result))
        assert ("world file '%s' cannot be loaded: %s" % (path, reason)
                in result.stdout + result.stderr), (path, output(result))


def test_missing_world_file_ends_gzserver_naming_the_folders_looked_in(ros):
    result = run(ros, 'rosrun', 'gazebo_ros', 'gzserver', 'worlds/no_such.world',
                 env={'GAZEBO_RESOURCE_PATH': '/nonexistent/gazebo'})
    assert result.returncode == 1, output(result)
    assert ("world file 'worlds/no_such.world' not found (looked in %s, %s/src/onedof_sim, "
            "/nonexistent/gazebo)" % (WORKSPACE, WORKSPACE)) in result.stdout + result.stderr, \
        output(result)


def test_world_file_found_in_gazebo_resource_path(ros, rospy_client, tmp_path):
    (tmp_path / 'worlds').mkdir()
    (tmp_path / 'worlds' / 'one_block.world').write_text(
        '<sdf version="1.6"><world name="w"><include><uri>model://toy_block</uri>'
        '<pose>0 0 0.0175 0 0 0</pose></include></world></sdf>')
    start_serving(ros, ['rosrun', 'gazebo_ros', 'gzserver', '-u', 'worlds/one_block.world'],
                  'gzserver', env={'GAZEBO_RESOURCE_PATH': str(tmp_path)})
    assert GazeboApi(rospy_client).get_world_properties().model_names == ['toy_block']


WORLDS = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'worlds')
# What the node logs at WARN and above, and what libsdformat prints as a warning or an error.
COMPLAINT_MARKS = ('[ WARN]', '[ERROR]', '[FATAL]', 'Warning [', 'Error [')


def assert_complaints(log, expected):
    """The complaints in the log are exactly those with the expected fragments, each present."""
    lines = [line for line in log.splitlines() if any(mark in line for mark in COMPLAINT_MARKS)]
    for fragment in expected:
        assert any(fragment in line for line in lines), (fragment, lines)
    assert [line for line in lines if not any(fragment in line for fragment in expected)] == [], \
        lines


def start_world(ros, engine, world):
    """gzserver on `world`, paused, with /gazebo/step_simulation (the test steps it)."""
    return start_serving(ros, ['rosrun', 'gazebo_ros', 'gzserver', '-u', '-e', engine,
                               os.path.join(WORLDS, world), '_enable_step_simulation:=true'],
                         'gzserver')


def yaw(orientation):
    return 2 * math.atan2(orientation.z, orientation.w)


@pytest.mark.parametrize('engine', ENGINES)
def test_a_world_saved_by_gazebo_11_loads_as_gazebo_loads_it(ros, rospy_client, engine):
    """Its <plane> ground, <script> materials, light, GUI camera and the rest load without a
    warning, as under Gazebo; its <state> places each model and sets the clock, as Gazebo's
    World::Load applies it."""
    gzserver = start_world(ros, engine, 'gazebo11_saved.world')
    api = GazeboApi(rospy_client)
    world = api.get_world_properties()
    assert world.model_names == ['ground_plane', 'unit_box', 'cafe_table', 'one_DOF_robot']
    assert world.sim_time == pytest.approx(91.335, abs=1e-9)
    box = api.get_model_state('unit_box', '').pose
    assert (box.position.x, box.position.y, box.position.z) == \
        pytest.approx((2.5, -1.5, 0.499995), abs=1e-9)
    assert yaw(box.orientation) == pytest.approx(1.2, abs=1e-9)
    assert api.get_model_properties('cafe_table').is_static
    assert api.get_joint_properties('joint1').success

    stepped = api.step_simulation(1000)
    assert stepped.success, stepped.status_message
    assert (stepped.sim_time.to_nsec(), stepped.iterations) == (92335000000, 92335)
    box = api.get_model_state('unit_box', '')
    assert (box.pose.position.x, box.pose.position.z) == pytest.approx((2.5, 0.5), abs=2e-3)
    assert abs(box.twist.linear.z) < 1e-3
    log = ros.log_text(gzserver)
    assert "world 'default': saved <state> applied: sim time 91.335 s, iteration 91335" in log, log
    assert_complaints(log, [])


# Worlds in the shapes of gazebo_ros_pkgs' test worlds: each world's models, and the complaints
# it draws: libsdformat's warnings (Gazebo's libsdformat gives them too), the errors Gazebo logs
# for a plugin or a mesh it cannot load.
UPSTREAM_SHAPES = {
    'camera_test_shape.world': (['ground_plane', 'ball', 'pole'], []),
    'sensor_test_shape.world': (
        ['sonar_post', 'profiler', 'slope', 'gripper_finger'],
        ['XML Attribute[cast_shadows] in element[light] not defined in SDF',
         'XML Attribute[display] in element[scan] not defined in SDF',
         'XML Attribute[near] in element[clip] not defined in SDF',
         'XML Attribute[far] in element[clip] not defined in SDF',
         "model 'gripper_finger': link 'link': collision 'finger_mesh' is the mesh "
         "'pr2/gripper/finger_tip.stl', which is not found"]),
    'old_sdf_test_shape.world': (
        ['floor', 'crate', 'lift'],
        ['XML Attribute[name] in element[collision] not defined in SDF',
         'Non-unique name[door] detected 2 times in XML children of model with name[lift]',
         'Joint with name [door] in model with name [lift] has a name collision']),
    'p2dx_test_shape.world': (
        ['ground_plane', 'two_wheeler'],
        ["model 'two_wheeler': Failed to load plugin libDiffDrivePlugin.so (plugin "
         "'diff_drive')"]),
}


@pytest.mark.parametrize('engine', ENGINES)
@pytest.mark.parametrize('world', sorted(UPSTREAM_SHAPES))
def test_worlds_in_the_shapes_of_gazebos_test_worlds_load(ros, rospy_client, engine, world):
    gzserver = start_world(ros, engine, world)
    api = GazeboApi(rospy_client)
    models, expected = UPSTREAM_SHAPES[world]
    assert api.get_world_properties().model_names == models
    api.run_for(5 * 10 ** 8)
    for name in models:
        for body in api.get_model_properties(name).body_names:
            state = api.get_link_state(name + '::' + body, '').link_state
            position = state.pose.position
            assert all(math.isfinite(v) for v in (position.x, position.y, position.z)), \
                (name, body, state)
    assert_complaints(ros.log_text(gzserver), expected)
