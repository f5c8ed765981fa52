"""gazebo_ros' world launch files (shapes, rubble, mud, elevator, willowgarage, range) and the
models of Gazebo's database this workspace ships, run as a user types them against the real
simulator on every engine; the engine chosen by the node's ~physics parameter set beforehand when
a launch file passes no physics; and enable_ros_network:=false, which leaves out every /gazebo
service and topic as Gazebo does."""
import pytest

from api_client import GazeboApi
from conftest import ENGINES
from gazebo_commands import output, run, start_serving
from onedof_harness.private_ros import wait_until

HEADLESS = {'DISPLAY': ''}
# The models each world places (/gazebo/model_states), and the plugins it names that this
# simulator does not have (each said to be not simulated or ignored at start-up).
WORLDS = {
    'shapes': ({'ground_plane', 'box', 'sphere', 'cylinder'}, []),
    'rubble': ({'ground_plane'}, ['libRubblePlugin.so']),
    'mud': ({'ground_plane', 'pendulum_thick_mud', 'pendulum_thin_mud', 'pendulum_no_mud',
             'mud_pit_thin', 'mud_pit_thick'}, ['libMudPlugin.so']),
    'elevator': ({'ground_plane', 'elevator', 'elevator_shaft', 'floor0', 'floor1'},
                 ['libgazebo_ros_elevator.so', 'libSimEventsPlugin.so']),
}


def model_names(rospy):
    from gazebo_msgs.msg import ModelStates
    return set(rospy.wait_for_message('/gazebo/model_states', ModelStates, timeout=60).name)


def engine_of(api):
    status = api.get_physics_properties().status_message
    return next(name for name in ENGINES if '(engine: %s)' % name in status)


@pytest.mark.parametrize('engine', ENGINES)
@pytest.mark.parametrize('world', sorted(WORLDS))
def test_world_launch_file_starts_its_world(ros, rospy_client, world, engine):
    """The launch file passes no physics: the engine is the node's ~physics set beforehand."""
    models, missing_plugins = WORLDS[world]
    ros.set_param('/gazebo/physics', engine)
    launch = start_serving(ros, ['roslaunch', 'gazebo_ros', world + '_world.launch'], 'roslaunch',
                           env=HEADLESS)
    api = GazeboApi(rospy_client)
    assert engine_of(api) == engine
    assert model_names(rospy_client) == models
    log = ros.log_text(launch)
    for plugin in missing_plugins:
        assert plugin in log, log


@pytest.mark.parametrize('engine', ENGINES)
def test_shapes_world_shapes_rest_on_the_ground(ros, rospy_client, engine):
    """Gazebo's shapes.world: the 1 m box, sphere and cylinder stay where they rest."""
    ros.set_param('/gazebo/physics', engine)
    start_serving(ros, ['roslaunch', 'gazebo_ros', 'shapes_world.launch'], 'roslaunch',
                  env=HEADLESS)
    api = GazeboApi(rospy_client)
    api.run_for(1_000_000_000)
    expected = {'box': (0, 0, 0.5), 'sphere': (0, 1.5, 0.5), 'cylinder': (0, -1.5, 0.5)}
    for name, position in expected.items():
        p = api.get_model_state(name, 'world').pose.position
        assert (p.x, p.y, p.z) == pytest.approx(position, abs=0.01), name


def test_willowgarage_world_names_the_model_it_lacks(ros):
    launch = ros.start(['roslaunch', 'gazebo_ros', 'willowgarage_world.launch'], name='roslaunch',
                       env=HEADLESS, may_exit=True)
    wait_until(lambda: 'model://willowgarage' in ros.log_text(launch), 60,
               what='the simulator to name model://willowgarage')


def test_range_world_launch_takes_a_world_of_gazebo_plugins(ros, rospy_client, tmp_path):
    """range_world.launch's world:=NAME is gazebo_plugins' test/test_worlds/NAME.world."""
    package = tmp_path / 'gazebo_plugins'
    (package / 'test' / 'test_worlds').mkdir(parents=True)
    (package / 'package.xml').write_text(
        '<package format="2"><name>gazebo_plugins</name><version>0.0.0</version>'
        '<description>test</description><maintainer email="a@b.c">t</maintainer>'
        '<license>BSD</license></package>')
    (package / 'test' / 'test_worlds' / 'one_table.world').write_text(
        '<sdf version="1.6"><world name="default"><include><uri>model://table</uri></include>'
        '</world></sdf>')
    env = dict(HEADLESS, ROS_PACKAGE_PATH='%s:%s' % (tmp_path, ros.env['ROS_PACKAGE_PATH']))
    start_serving(ros, ['roslaunch', 'gazebo_ros', 'range_world.launch', 'world:=one_table',
                        'gui:=false', 'physics:=' + ENGINES[-1]], 'roslaunch', env=env)
    assert engine_of(GazeboApi(rospy_client)) == ENGINES[-1]
    assert model_names(rospy_client) == {'table'}


def test_physics_argument_beats_the_parameter_set_beforehand(ros, rospy_client):
    ros.set_param('/gazebo/physics', ENGINES[-1])
    start_serving(ros, ['roslaunch', 'gazebo_ros', 'empty_world.launch', 'gui:=false',
                        'physics:=' + ENGINES[0]], 'roslaunch', env=HEADLESS)
    assert engine_of(GazeboApi(rospy_client)) == ENGINES[0]


# --- the models of Gazebo's database ---------------------------------------------------------

# name -> (spawn height, the model frame's height once it rests; None: static)
DATABASE_MODELS = {
    'checkerboard_plane': (0.0, None),
    'table': (0.0, None),
    'bookshelf': (0.0, None),
    'coke_can': (0.05, -0.0025),
    'double_pendulum_with_base': (0.0, 0.0),
}


@pytest.mark.parametrize('engine', ENGINES)
def test_database_models_spawn_and_rest(ros, rospy_client, engine):
    """spawn_model -database NAME for each: the free ones fall onto the ground and rest."""
    start_serving(ros, ['rosrun', 'gazebo_ros', 'gzserver', '-e', engine], 'gzserver')
    api = GazeboApi(rospy_client)
    for index, (name, (z, _)) in enumerate(sorted(DATABASE_MODELS.items())):
        result = run(ros, 'rosrun', 'gazebo_ros', 'spawn_model', '-database', name, '-sdf',
                     '-model', name, '-x', str(3.0 * index), '-z', str(z))
        assert result.returncode == 0, output(result)
    assert set(api.get_world_properties().model_names) == set(DATABASE_MODELS)
    api.run_for(2_000_000_000)
    for index, (name, (_, rest_z)) in enumerate(sorted(DATABASE_MODELS.items())):
        p = api.get_model_state(name, 'world').pose.position
        assert p.x == pytest.approx(3.0 * index, abs=0.01), name
        if rest_z is not None:
            assert p.z == pytest.approx(rest_z, abs=0.005), name


# --- enable_ros_network ------------------------------------------------------------------------

def graph_names(rospy):
    """(topics published or subscribed, services) of the whole graph, from the master."""
    import rosgraph
    publishers, subscribers, services = rosgraph.Master('/test').getSystemState()
    topics = {topic for topic, _ in publishers} | {topic for topic, _ in subscribers}
    return topics, {service for service, _ in services}


P3D_WORLD = """<sdf version="1.6"><world name="default"><model name="probe"><static>true</static>
<link name="link"><collision name="c"><geometry><box><size>0.1 0.1 0.1</size></box></geometry>
</collision></link><plugin name="p3d" filename="libgazebo_ros_p3d.so"><bodyName>link</bodyName>
<topicName>probe_pose</topicName><frameName>world</frameName><updateRate>10</updateRate>
</plugin></model></world></sdf>"""


@pytest.mark.parametrize('engine', ENGINES)
def test_ros_network_disabled_serves_no_gazebo_name(ros, rospy_client, engine, tmp_path):
    """enable_ros_network:=false: of the node's names only /clock and its logger services stay
    (gazebo_ros' no_gazebo_network_api.yaml); the world runs and its models' plugins publish."""
    world = tmp_path / 'probe.world'
    world.write_text(P3D_WORLD)
    launch = ros.start(['roslaunch', 'gazebo_ros', 'empty_world.launch', 'gui:=false',
                        'enable_ros_network:=false', 'physics:=' + engine,
                        'world_name:=%s' % world], name='roslaunch', env=HEADLESS)
    from nav_msgs.msg import Odometry
    odometry = rospy_client.wait_for_message('/probe_pose', Odometry, timeout=60)
    assert odometry.header.stamp.to_sec() > 0, 'sim time runs'
    assert 'ROS gazebo topics/services are disabled' in ros.log_text(launch)
    topics, services = graph_names(rospy_client)
    assert {t for t in topics if t.startswith('/gazebo/')} == set()
    assert '/clock' in topics and '/probe_pose' in topics
    assert {s for s in services if s.startswith('/gazebo/')} == {
        '/gazebo/get_loggers', '/gazebo/set_logger_level'}


def test_ros_network_enabled_by_default_serves_the_api(ros, rospy_client):
    start_serving(ros, ['roslaunch', 'gazebo_ros', 'empty_world.launch', 'gui:=false'],
                  'roslaunch', env=HEADLESS)
    topics, services = graph_names(rospy_client)
    assert {'/gazebo/model_states', '/gazebo/link_states', '/gazebo/set_model_state',
            '/gazebo/parameter_updates'} <= topics
    assert {'/gazebo/spawn_sdf_model', '/gazebo/get_model_state',
            '/gazebo/set_physics_properties'} <= services
