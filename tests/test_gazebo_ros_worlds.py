"""gazebo_ros' world launch files (shapes, rubble, mud, elevator, willowgarage, range) and the
models of Gazebo's database this workspace ships, run as a user types them against the real
simulator on every engine; the engine chosen by the node's ~physics parameter set beforehand when
a launch file passes no physics; and enable_ros_network:=false, which leaves out every /gazebo
service and topic as Gazebo does."""
import pytest

from api_client import GazeboApi
from conftest import ENGINES, GROUND
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
    """spawn_model -database NAME for each: the free ones fall onto the ground (gzserver's
    default world's ground_plane) and rest."""
    start_serving(ros, ['rosrun', 'gazebo_ros', 'gzserver', '-e', engine], 'gzserver')
    api = GazeboApi(rospy_client)
    for index, (name, (z, _)) in enumerate(sorted(DATABASE_MODELS.items())):
        result = run(ros, 'rosrun', 'gazebo_ros', 'spawn_model', '-database', name, '-sdf',
                     '-model', name, '-x', str(3.0 * index), '-z', str(z))
        assert result.returncode == 0, output(result)
    assert set(api.get_world_properties().model_names) == {GROUND} | set(DATABASE_MODELS)
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


# What the Gazebo window runs (gazebo_ros' gzclient: rviz and the model handles, the wrench
# dialogs), as words of a process's command line.
WINDOW_WORDS = ('gzclient', 'rviz', 'model_handles', 'wrench_dialog', 'world_view')


def test_without_gui_no_window_runs_and_nothing_subscribes_to_the_simulator(ros, rospy_client):
    """gui:=false on a display where a window could open: no process of the window runs and no
    node but the simulator's and rosout's is in the graph; nothing subscribes to what the
    simulator publishes (rosout to its log alone), and it was not asked for its markers. The
    window, absent, costs the simulator nothing."""
    import psutil
    import rosgraph
    import rosnode
    from onedof_sim.tutorial.rviz_view import start_xvfb
    xvfb, display = start_xvfb(ros)
    launch = start_serving(ros, ['roslaunch', 'gazebo_ros', 'empty_world.launch', 'gui:=false',
                                 'paused:=false'], 'roslaunch', env={'DISPLAY': display})
    api = GazeboApi(rospy_client)
    wait_until(lambda: api.get_world_properties().sim_time > 0.5, 60, what='the world running')
    started = [' '.join(child.cmdline())
               for child in psutil.Process(launch.pid).children(recursive=True)]
    assert not [command for command in started if any(word in command for word in WINDOW_WORDS)]
    me = rospy_client.get_name()
    assert set(rosnode.get_node_names()) - {me} == {'/gazebo', '/rosout'}
    publishers, subscribers, _ = rosgraph.Master('/test').getSystemState()
    published = {topic for topic, nodes in publishers if '/gazebo' in nodes}
    listeners = {topic: set(nodes) - {me} for topic, nodes in subscribers if topic in published}
    assert {topic: nodes for topic, nodes in listeners.items() if nodes} == {
        '/rosout': {'/rosout'}}
    assert not rospy_client.has_param('/gazebo/enable_collision_markers')
    assert launch.poll() is None, ros.log_text(launch)
    ros.terminate(launch)
    ros.terminate(xvfb)


# Gazebo's names (docs/gazebo-api.md, "Every name the node advertises"): what the node publishes,
# what it subscribes to (no publisher of its own) and the services it serves, with their types.
GAZEBO_PUBLISHED = {
    '/clock': 'rosgraph_msgs/Clock',
    '/rosout': 'rosgraph_msgs/Log',
    '/gazebo/model_states': 'gazebo_msgs/ModelStates',
    '/gazebo/link_states': 'gazebo_msgs/LinkStates',
    '/gazebo/parameter_descriptions': 'dynamic_reconfigure/ConfigDescription',
    '/gazebo/parameter_updates': 'dynamic_reconfigure/Config',
}
GAZEBO_SUBSCRIBED = {
    '/gazebo/set_model_state': 'gazebo_msgs/ModelState',
    '/gazebo/set_link_state': 'gazebo_msgs/LinkState',
}
GAZEBO_SERVICES = {'/gazebo/' + name: 'gazebo_msgs/' + srv for name, srv in [
    ('apply_body_wrench', 'ApplyBodyWrench'), ('apply_joint_effort', 'ApplyJointEffort'),
    ('clear_body_wrenches', 'BodyRequest'), ('clear_joint_forces', 'JointRequest'),
    ('delete_light', 'DeleteLight'), ('delete_model', 'DeleteModel'),
    ('get_joint_properties', 'GetJointProperties'),
    ('get_light_properties', 'GetLightProperties'), ('get_link_properties', 'GetLinkProperties'),
    ('get_link_state', 'GetLinkState'), ('get_model_properties', 'GetModelProperties'),
    ('get_model_state', 'GetModelState'), ('get_physics_properties', 'GetPhysicsProperties'),
    ('get_world_properties', 'GetWorldProperties'), ('set_joint_properties', 'SetJointProperties'),
    ('set_light_properties', 'SetLightProperties'), ('set_link_properties', 'SetLinkProperties'),
    ('set_link_state', 'SetLinkState'), ('set_model_configuration', 'SetModelConfiguration'),
    ('set_model_state', 'SetModelState'), ('set_physics_properties', 'SetPhysicsProperties'),
    ('spawn_sdf_model', 'SpawnModel'), ('spawn_urdf_model', 'SpawnModel')]}
GAZEBO_SERVICES.update({
    '/gazebo/pause_physics': 'std_srvs/Empty', '/gazebo/unpause_physics': 'std_srvs/Empty',
    '/gazebo/reset_simulation': 'std_srvs/Empty', '/gazebo/reset_world': 'std_srvs/Empty',
    '/gazebo/set_parameters': 'dynamic_reconfigure/Reconfigure',
    '/gazebo/get_loggers': 'roscpp/GetLoggers',
    '/gazebo/set_logger_level': 'roscpp/SetLoggerLevel',
})
# The simulator's own names, served when asked for.
STEP_SERVICE = {'/gazebo/step_simulation': 'onedof_sim/StepSimulation'}
# The world view's markers (~enable_collision_markers), one topic per item of Gazebo's View menu,
# and the window's own streams at the views' rate: the sim time and the models' states.
MARKERS_TOPIC = dict({'/gazebo/' + view + '_markers': 'visualization_msgs/MarkerArray'
                      for view in ('visual', 'collision', 'joint', 'com', 'inertia', 'contact')},
                     **{'/gazebo/view_clock': 'rosgraph_msgs/Clock',
                        '/gazebo/view_model_states': 'gazebo_msgs/ModelStates'})
# The world view's service, served with its markers: one model back at its spawn pose.
VIEW_SERVICE = {'/gazebo/reset_model': 'onedof_sim/ResetModel'}


def simulator_names(rospy):
    """({topic: type} the node /gazebo publishes, {topic: type} it subscribes to, {service:
    type} it serves), from the master and (the services' types) from the services themselves."""
    import rosgraph
    import rosservice
    master = rosgraph.Master('/test')
    publishers, subscribers, services = master.getSystemState()
    types = dict(master.getTopicTypes())

    def of_node(entries):
        return {name for name, nodes in entries if '/gazebo' in nodes}
    return ({topic: types[topic] for topic in of_node(publishers)},
            {topic: types[topic] for topic in of_node(subscribers)},
            {service: rosservice.get_service_type(service) for service in of_node(services)})


def publishers_of(topic):
    import rosgraph
    publishers, _, _ = rosgraph.Master('/test').getSystemState()
    return next((nodes for name, nodes in publishers if name == topic), [])


@pytest.mark.parametrize('engine', ENGINES)
def test_by_default_the_simulator_advertises_exactly_gazebos_names(ros, rospy_client, engine):
    """As gazebo_ros' ros_network_default.test starts it: every topic and service of the node,
    with its type, is Gazebo's, and every one of Gazebo's is there; /clock has it as its only
    publisher, the set_*_state topics none. The step service is not there, and the tools say
    which parameter serves it; the markers come and go with their parameter while it runs."""
    from onedof_sim.simulator_extras import step_service
    start_serving(ros, ['roslaunch', 'gazebo_ros', 'empty_world.launch', 'paused:=false',
                        'gui:=false', 'enable_ros_network:=true', 'physics:=' + engine],
                  'roslaunch', env=HEADLESS)
    published, subscribed, services = simulator_names(rospy_client)
    assert published == GAZEBO_PUBLISHED
    assert subscribed == GAZEBO_SUBSCRIBED
    assert services == GAZEBO_SERVICES
    assert publishers_of('/clock') == ['/gazebo']
    for topic in GAZEBO_SUBSCRIBED:
        assert publishers_of(topic) == []

    with pytest.raises(RuntimeError, match='~enable_step_simulation'):
        step_service(rospy_client)

    rospy_client.set_param('/gazebo/enable_collision_markers', True)
    wait_until(lambda: publishers_of('/gazebo/collision_markers') == ['/gazebo'], 60,
               what='the simulator to publish its markers once asked')
    wait_until(lambda: simulator_names(rospy_client)[2] == dict(GAZEBO_SERVICES, **VIEW_SERVICE),
               60, what="the simulator to serve the view's reset_model with its markers")
    assert simulator_names(rospy_client)[0] == dict(GAZEBO_PUBLISHED, **MARKERS_TOPIC)
    rospy_client.set_param('/gazebo/enable_collision_markers', False)
    wait_until(lambda: publishers_of('/gazebo/collision_markers') == [], 60,
               what='the simulator to take its markers down')
    wait_until(lambda: simulator_names(rospy_client)[2] == GAZEBO_SERVICES, 60,
               what="the simulator to take the view's reset_model down")


@pytest.mark.parametrize('arguments, step, markers', [
    (['enable_step_simulation:=true', 'enable_collision_markers:=true'], True, True),
    (['lockstep:=true'], True, False),
    (['lockstep:=true', 'enable_step_simulation:=false'], False, False),
])
def test_the_simulators_own_names_are_there_when_asked_for(ros, rospy_client, arguments, step,
                                                           markers):
    """Gazebo's names and the two asked for: the step service (lock-step implies it, unless
    refused) and the world view's markers, with its reset_model."""
    launch = start_serving(ros, ['roslaunch', 'gazebo_ros', 'empty_world.launch', 'gui:=false'] +
                           arguments, 'roslaunch', env=HEADLESS)
    published, subscribed, services = simulator_names(rospy_client)
    assert published == dict(GAZEBO_PUBLISHED, **(MARKERS_TOPIC if markers else {}))
    assert subscribed == GAZEBO_SUBSCRIBED
    assert services == dict(GAZEBO_SERVICES, **(STEP_SERVICE if step else {}),
                            **(VIEW_SERVICE if markers else {}))
    if step:
        assert 'with step_simulation' in ros.log_text(launch)
