"""Bad input over real ROS: the node answers with what is wrong, naming the field and the accepted
range, keeps its world as it was and goes on answering and stepping.

One simulator per engine serves the whole module (conftest's shared_sim), started paused; before
each test the world is reset to the tutorial robot alone with the default physics.
"""
import math
import os
import threading

import pytest

from api_client import (BOX_SDF, ROBOT, STEP_NS, GazeboApi, fixed_chain_sdf, pose,
                        ros_duration, ros_time, tutorial_urdf)
from conftest import GROUND, start_sim
from onedof_harness.private_ros import wait_until

DEFAULT_RATE = 1000.0
BOX_MASS = 1.0


@pytest.fixture
def api(shared_sim):
    """The module's simulator (conftest's shared_sim: paused at 0, the ground plane alone, the
    start-up physics) with the tutorial robot at rest."""
    shared_sim.spawn_robot()
    return shared_sim


def set_physics(api, time_step=None, max_update_rate=None, cfm=None, gravity_z=-9.8):
    physics = api.get_physics_properties()
    physics.gravity.x, physics.gravity.y, physics.gravity.z = 0.0, 0.0, gravity_z
    if cfm is not None:
        physics.ode_config.cfm = cfm
    return api.set_physics_properties(
        physics.time_step if time_step is None else time_step,
        physics.max_update_rate if max_update_rate is None else max_update_rate,
        physics.gravity, physics.ode_config)


def world_state(api):
    """What a refused request must leave as it was: sim time, models, every link's pose and twist."""
    world = api.get_world_properties()
    links = []
    for model in world.model_names:
        for body in api.get_model_properties(model).body_names:
            state = api.get_link_state(model + '::' + body, '').link_state
            links.append((model, body, state.pose, state.twist))
    return world.sim_time, world.model_names, links


def assert_refused(res, *texts):
    assert not res.success, res.status_message
    for text in texts:
        assert text in res.status_message


def assert_still_running(api):
    """The node answers and steps, and the robot swings from a tipped position."""
    assert api.set_model_configuration(ROBOT, '', ['joint1'], [0.3]).success
    api.run_for(100 * STEP_NS)
    position, rate = api.joint()
    assert position != 0.3 and rate != 0.0


def urdf_with_link2_inertial(mass, ixx):
    urdf = tutorial_urdf()
    link2 = urdf.index('<link name="link2">')
    begin = urdf.index('<inertial>', link2)
    end = urdf.index('</inertial>', begin) + len('</inertial>')
    inertial = ('<inertial><origin xyz="0 0 0.5"/><mass value="%r"/><inertia ixx="%r" ixy="0" '
                'ixz="0" iyy="0.1" iyz="0" izz="0.005"/></inertial>' % (mass, ixx))
    return urdf[:begin] + inertial + urdf[end:]


def spawn_urdf(api, name, urdf, z=0.0):
    return api.spawn_urdf_model(name, urdf, '', pose(z=z), '')


# --- huge but finite values: refused, the node keeps serving -------------------------------------

def test_huge_but_finite_values_are_refused_naming_the_field_and_range(api):
    from gazebo_msgs.msg import LinkState, ModelState
    before = world_state(api)
    state = ModelState(model_name=ROBOT, pose=pose())
    state.twist.linear.x = 1.0e308
    assert_refused(api.set_model_state(state), 'SetModelState: the speed |twist.linear| must be '
                   'at most 100 m/s')
    link = LinkState(link_name=ROBOT + '::link2', pose=pose())
    link.twist.angular.z = 1.0e308
    assert_refused(api.set_link_state(link), 'SetLinkState: the speed |twist.angular| must be at '
                   'most 100 rad/s')
    link = LinkState(link_name=ROBOT + '::link2', pose=pose(y=1.0e308))
    assert_refused(api.set_link_state(link),
                   'SetLinkState: each pose.position component must be in [-1e+06, 1e+06] m')
    # A quaternion whose norm overflows cannot be normalised: said so, not called zero.
    overflowing = pose()
    overflowing.orientation.w = 1.0e308
    for res in (api.set_model_state(ModelState(model_name=ROBOT, pose=overflowing)),
                api.spawn_sdf_model('turned', BOX_SDF, '', overflowing, '')):
        assert_refused(res, 'the orientation quaternion cannot be normalised: its norm is not '
                       'finite')
        assert 'is zero' not in res.status_message
    res = api.apply_body_wrench(ROBOT + '::link2', '', _point(x=1.0e308), _wrench(fz=1.0),
                                ros_time(0), ros_duration(10 * STEP_NS))
    assert_refused(res, 'ApplyBodyWrench: each reference_point component must be in '
                   '[-1e+06, 1e+06] m')
    assert_refused(spawn_urdf(api, 'heavy', urdf_with_link2_inertial(1.0, 1.0e308)),
                   "SpawnModel: link 'link2' has an inertia component of 1e+308 kg m^2")
    # A moment of 1e-300 is lost in rounding once link2's inertia is moved to its centre of mass:
    # refused as no rigid body's, or as out of range.
    assert_refused(spawn_urdf(api, 'thin', urdf_with_link2_inertial(1.0, 1.0e-300)),
                   "SpawnModel: link 'link2' ", 'inertia')
    # The same values on the topics: dropped, with the reason logged.
    topic_state = ModelState(model_name=ROBOT, pose=pose(z=1.0e308))
    _publish_until_read(api, '/gazebo/set_model_state', ModelState, topic_state)
    topic_link = LinkState(link_name=ROBOT + '::link2', pose=pose(x=1.0e308))
    _publish_until_read(api, '/gazebo/set_link_state', LinkState, topic_link)
    assert world_state(api) == before
    assert_still_running(api)


def free_box_urdf(side, mass, solid_fraction):
    """A free box whose moments are solid_fraction of a solid box's of that mass and side."""
    moment = solid_fraction * mass * side * side / 6
    return ('<robot name="box"><link name="body"><inertial><mass value="%r"/><inertia ixx="%r" '
            'ixy="0" ixz="0" iyy="%r" iyz="0" izz="%r"/></inertial><collision><geometry>'
            '<box size="%r %r %r"/></geometry></collision></link></robot>'
            % (mass, moment, moment, moment, side, side, side))


def test_a_body_whose_inertia_is_far_below_its_shape_is_spawned_with_a_warning_and_contained(
        api):
    """A 0.2 m box of 1 g with a millionth of its solid moments aborted ODE's contact solver
    once it touched the ground, where nothing contained it. Gazebo spawns it, and so does the
    node, with a warning that names the link and the least plausible moment; what the engine
    then does with it is contained (the step taken again, or the box removed): the world keeps
    stepping finite values and the node answers. The same box with its solid moments spawns
    without a warning and comes to rest."""
    # Clear of the robot, as is the solid box.
    res = api.spawn_urdf_model('hollow_box', free_box_urdf(0.2, 0.001, 1e-6), '',
                               pose(x=-3.0, z=0.3), '')
    assert res.success, res.status_message
    assert ("SpawnModel: Successfully spawned entity; warning: link 'body' (with the links "
            "welded to it) has a smallest principal moment of inertia of 6.66667e-12 kg m^2, "
            "implausibly small for its collision shape (realistic: at least 3e-08 kg m^2)"
            in res.status_message), res.status_message
    api.run_for(1000 * STEP_NS)
    world = api.get_world_properties()
    for name in world.model_names:
        for body in api.get_model_properties(name).body_names:
            state = api.get_link_state(name + '::' + body, '').link_state
            values = (state.pose.position.x, state.pose.position.y, state.pose.position.z,
                      state.twist.linear.x, state.twist.linear.y, state.twist.linear.z)
            assert all(math.isfinite(v) for v in values), (name, body, state)
    assert_still_running(api)
    res = api.spawn_urdf_model('solid_box', free_box_urdf(0.2, 0.001, 1.0), '',
                               pose(x=3.0, z=0.3), '')
    assert res.success and 'warning' not in res.status_message, res.status_message
    api.run_for(1000 * STEP_NS)
    state = api.get_model_state('solid_box', '')
    assert abs(state.pose.position.z - 0.1) < 0.005


def _point(x=0.0, y=0.0, z=0.0):
    from geometry_msgs.msg import Point
    return Point(x, y, z)


def _wrench(fz=0.0):
    from geometry_msgs.msg import Wrench
    wrench = Wrench()
    wrench.force.z = fz
    return wrench


def _publish_until_read(api, topic, message_type, message):
    """Publishes on one of the node's set_*_state topics and waits until the node logs the refusal
    (a topic has no reply: the node's log is its only answer)."""
    import rospy
    from rosgraph_msgs.msg import Log
    from onedof_harness.private_ros import wait_until
    logged = []
    log = rospy.Subscriber('/rosout_agg', Log, lambda entry: logged.append(entry.msg))
    publisher = rospy.Publisher(topic, message_type, queue_size=1, latch=True)
    wait_until(lambda: log.get_num_connections() > 0 and publisher.get_num_connections() > 0, 30,
               what='connections on /rosout_agg and ' + topic)
    publisher.publish(message)
    wait_until(lambda: any('pose.position component must be in' in text for text in logged), 30,
               what='the refusal of %s to be logged' % topic)
    publisher.unregister()
    log.unregister()


# --- a model too large to load: refused before it reaches the engine -----------------------------

def fixed_chain_urdf(links):
    parts = ['<robot name="chain"><link name="l0"><inertial><mass value="1"/><inertia ixx="1" '
             'ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>']
    for i in range(1, links):
        parts.append('<link name="l%d"/><joint name="j%d" type="fixed"><parent link="l%d"/>'
                     '<child link="l%d"/><origin xyz="0 0 0.001"/></joint>' % (i, i, i - 1, i))
    parts.append('</robot>')
    return ''.join(parts)


def test_a_model_beyond_the_size_limit_is_refused(api):
    before = world_state(api)
    assert_refused(spawn_urdf(api, 'chain', fixed_chain_urdf(20000)),
                   'SpawnModel: the model has 20000 links; at most 1000 are accepted')
    assert world_state(api) == before
    assert_still_running(api)


def test_an_sdf_past_the_link_limit_is_refused_and_the_largest_accepted(api):
    """The link count is read off the XML before libsdformat parses it."""
    before = world_state(api)
    assert_refused(api.spawn_sdf_model('chain', fixed_chain_sdf(3000), '', pose(), ''),
                   'SpawnModel: the model has 3000 links; at most 1000 are accepted')
    assert world_state(api) == before
    res = api.spawn_sdf_model('chain', fixed_chain_sdf(1000), '', pose(x=2.0), '')
    assert res.success, res.status_message
    assert_still_running(api)


def test_a_chain_past_the_exact_solvers_joint_limit_is_refused_on_ode(api, engine):
    """ODE's default solver (dWorldStep) costs about 1 ms a step at 50 moving joints and grows as
    joints^2.8 (999: seconds a step); Bullet's grows linearly and takes the chain. MuJoCo's model
    text nests each link in its parent, and Debian's XML reader stops at 100 levels: the mujoco
    engine refuses a chain deeper than 95 links, naming the limit."""
    from onedof_sim.benchmark.report import chain_urdf
    res = spawn_urdf(api, 'chain', chain_urdf(999))
    if engine == 'ode':
        assert_refused(res, 'SpawnModel: the model has 999 moving joints; at most 50 are accepted '
                            'with the exact solver', "with quick_step (the node's ~quick_step")
        assert api.get_world_properties().model_names == [GROUND, ROBOT]
    elif engine == 'mujoco':
        assert_refused(res, 'mujoco: a chain of more than 95 links below one another not supported')
        assert api.get_world_properties().model_names == [GROUND, ROBOT]
    else:
        assert res.success, res.status_message
    assert_still_running(api)


def test_an_included_file_that_is_no_regular_file_is_refused_before_it_is_opened(
        ros, engine, rospy_client, tmp_path):
    """A FIFO (whose open waits for a writer), a device or a folder where an <include>d model's
    model.sdf or model.config is, or where its mesh is: each spawn answers at once, refused in
    the words of a missing file (the mesh's collision left out, as a missing mesh), and the node
    serves others and takes the next spawn. Nothing ever writes the FIFOs: a reader that opened
    one would wait for ever."""
    def model_folder(name, config=True):
        folder = tmp_path / name
        folder.mkdir()
        if config:
            (folder / 'model.config').write_text(
                '<?xml version="1.0"?><model><name>%s</name><sdf version="1.6">model.sdf</sdf>'
                '</model>' % name)
        return folder
    os.mkfifo(str(model_folder('fifo_sdf') / 'model.sdf'))
    os.mkfifo(str(model_folder('fifo_config', config=False) / 'model.config'))
    (model_folder('device_sdf') / 'model.sdf').symlink_to('/dev/zero')
    (model_folder('folder_sdf') / 'model.sdf').mkdir()
    meshes = model_folder('fifo_mesh') / 'meshes'
    meshes.mkdir()
    os.mkfifo(str(meshes / 'block.stl'))
    (tmp_path / 'fifo_mesh' / 'model.sdf').write_text(
        '<sdf version="1.6"><model name="fifo_mesh"><link name="l"><collision name="c"><geometry>'
        '<mesh><uri>model://fifo_mesh/meshes/block.stl</uri></mesh></geometry></collision></link>'
        '</model></sdf>')
    start_sim(ros, engine, ['_paused:=true'], env={'GAZEBO_MODEL_PATH': str(tmp_path)})
    spawner, other = GazeboApi(rospy_client), GazeboApi(rospy_client)

    def spawn_within_deadline(name):
        including = ('<sdf version="1.6"><world name="w"><include><uri>model://%s</uri>'
                     '</include></world></sdf>' % name)
        answers = []
        spawning = threading.Thread(target=lambda: answers.append(
            spawner.spawn_sdf_model(name, including, '', pose(), '')), daemon=True)
        spawning.start()
        spawning.join(120)
        assert answers, 'the spawn of model://%s did not answer: its file was opened' % name
        return answers[0]

    for name in ('fifo_sdf', 'fifo_config', 'device_sdf', 'folder_sdf'):
        res = spawn_within_deadline(name)
        assert not res.success
        assert ('model://%s is not in the model path or is no readable regular file (' % name
                in res.status_message), res.status_message
        assert str(tmp_path) in res.status_message, res.status_message
        world = other.get_world_properties()
        assert world.success and world.model_names == [GROUND], name
    res = spawn_within_deadline('fifo_mesh')
    assert res.success, res.status_message
    assert ("the mesh 'model://fifo_mesh/meshes/block.stl', which is not found or not readable"
            in res.status_message), res.status_message
    assert other.get_model_properties('fifo_mesh').geom_names == []
    res = spawner.spawn_sdf_model('box', BOX_SDF, '', pose(), '')
    assert res.success, res.status_message
    assert other.step_simulation(10).success
    assert other.get_world_properties().model_names == [GROUND, 'fifo_mesh', 'box']


def test_a_spawn_inside_its_parse_blocks_no_other_client(ros, engine, rospy_client):
    """The node reads a model outside the world lock: another client's get_world_properties
    answers while the largest model accepted is read."""
    start_sim(ros, engine, ['_paused:=true'])
    spawner, other = GazeboApi(rospy_client), GazeboApi(rospy_client)
    other.get_world_properties()
    # The largest model accepted, a thousand links that libsdformat takes seconds to read: the
    # other client is answered while the spawn is in flight, and the spawn succeeds.
    spawned = []
    spawning = threading.Thread(target=lambda: spawned.append(
        spawner.spawn_sdf_model('largest', fixed_chain_sdf(1000), '', pose(), '')), daemon=True)
    spawning.start()
    answered_in_flight = 0
    while not spawned and spawning.is_alive():
        assert other.get_world_properties().success
        answered_in_flight += 0 if spawned else 1
    spawning.join(120)
    assert spawned and spawned[0].success, spawned
    assert answered_in_flight > 0
    assert other.get_world_properties().model_names == [GROUND, 'largest']


# --- time_step: within [1e-6, 0.1] s, so sim time stays within ROS time --------------------------

def test_time_step_outside_its_range_is_refused_with_the_range(api):
    for time_step in (1.0e6, 1.0e10):
        assert_refused(set_physics(api, time_step=time_step),
                       'SetPhysicsProperties: time_step must be in [1e-06, 0.1] s')
    assert api.get_physics_properties().time_step == 0.001
    assert_still_running(api)


# --- max_update_rate: 0 or 1 to 1e6 steps per wall second; a new one at once ---------------------

def test_a_crawling_max_update_rate_is_refused_and_a_new_rate_takes_effect_at_once(api):
    for rate in (0.01, 1.0e308):
        assert_refused(set_physics(api, max_update_rate=rate),
                       'SetPhysicsProperties: max_update_rate must be 0 (as fast as possible) or '
                       'between 1 and 1e+06 steps per wall second')
    assert api.get_physics_properties().max_update_rate == DEFAULT_RATE
    # The slowest accepted pace, then back: the loop re-reads the rate while it waits.
    assert set_physics(api, max_update_rate=1.0).success
    api.unpause_physics()
    assert set_physics(api, max_update_rate=DEFAULT_RATE).success
    api.pause_physics()
    assert_still_running(api)


# --- a huge wrench: clamped to what the reply says, and applied ----------------------------------

def test_a_huge_wrench_is_clamped_to_what_is_said_and_applied(api):
    assert api.spawn_sdf_model('box', BOX_SDF, '', pose(x=2.0, z=0.1), '').success
    api.run_for(100 * STEP_NS)  # settle on the ground
    resting = api.get_model_state('box', '').pose.position.z
    res = api.apply_body_wrench('box::body', 'box::body', _point(), _wrench(fz=1.0e200),
                                ros_time(0), ros_duration(10 * STEP_NS))
    assert res.success, res.status_message
    # The bound takes the box to the 100 m/s speed cap in 10 steps of 1 ms.
    bound = BOX_MASS * 100 / (10 * 0.001)
    assert res.status_message == (
        'ApplyBodyWrench: wrench set; force clamped to |force| %g N (same direction), the most '
        'this body takes without the simulation blowing up' % bound)
    api.run_for(10 * STEP_NS)
    state = api.get_model_state('box', '')
    assert state.pose.position.z > resting + 0.1
    assert state.twist.linear.z > 50


# --- joint positions: within [-1e6, 1e6] ---------------------------------------------------------

def test_a_joint_position_out_of_range_is_refused(api):
    before = world_state(api)
    assert_refused(api.set_model_configuration(ROBOT, '', ['joint1'], [1.0e17]),
                   "SetModelConfiguration: the position of joint 'joint1' must be in "
                   "[-1e+06, 1e+06] (rad or m)")
    assert world_state(api) == before
    assert_still_running(api)


# --- masses, positions and solver settings that would stop the whole world -----------------------

def test_input_that_would_stop_the_world_is_refused(api):
    from gazebo_msgs.msg import ModelState
    before = world_state(api)
    assert_refused(spawn_urdf(api, 'heavy', urdf_with_link2_inertial(1.0e308, 0.1), z=3.0),
                   "SpawnModel: link 'link2' has a mass of 1e+308 kg; a mass must be 0 or in "
                   "[1e-06, 1e+06] kg")
    assert_refused(api.set_model_state(ModelState(model_name=ROBOT, pose=pose(z=1.0e308))),
                   'SetModelState: each pose.position component must be in [-1e+06, 1e+06] m')
    assert_refused(set_physics(api, cfm=1.0e308), 'SetPhysicsProperties: cfm must be in [0, 10]')
    assert_refused(api.set_link_properties(ROBOT + '::link2', _com(), True, 1.0e308,
                                           0.1, 0.0, 0.0, 0.1, 0.0, 0.005),
                   'SetLinkProperties: mass must be 0 (a link carried by the one it is welded '
                   'to) or in [1e-06, 1e+06] kg')
    assert world_state(api) == before
    assert api.get_physics_properties().ode_config.cfm == 0.0
    assert_still_running(api)


def _com():
    from geometry_msgs.msg import Pose
    com = Pose()
    com.position.z = 0.5
    com.orientation.w = 1.0
    return com


# --- what urdfdom and libsdformat accept or only print: refused with the reason ------------------

INERTIAL = ('<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
            'izz="1"/></inertial>')


@pytest.mark.parametrize('xml,why', [
    ('<robot name="r"><link name="a">%s</link><link name="b">%s</link><joint name="j" '
     'type="continuous"><parent link="b"/><child link="b"/><axis xyz="0 0 1"/></joint></robot>'
     % (INERTIAL, INERTIAL),
     "SpawnModel: joint 'j' has link 'b' as both its parent and its child"),
    ('<robot name="r"><link name="a">%s<collision><geometry><box size="nan 1 1"/></geometry>'
     '</collision></link></robot>' % INERTIAL,
     'SpawnModel: invalid URDF: Unable to parse component [nan] to a double'),
    ('<sdf version="99"><model name="m"><link name="l"/></model></sdf>',
     "SpawnModel: invalid SDF: version '99' is not one this libsdformat reads (1.0 to 1.9)"),
], ids=['joint-parent-is-its-child', 'nan-box-size', 'sdf-version-99'])
def test_what_the_parsers_accept_or_only_print_is_refused_with_the_reason(api, xml, why):
    before = world_state(api)
    assert_refused(api.spawn_sdf_model('r', xml, '', pose(z=1.0), ''), why)
    assert world_state(api) == before


# --- model names that would make scoped names ambiguous ("one_DOF_robot::link2") -----------------

def test_model_names_that_make_scoped_names_ambiguous_are_refused(api):
    before = world_state(api)
    for name in (ROBOT + '::link2', 'world'):
        assert_refused(api.spawn_sdf_model(name, BOX_SDF, '', pose(x=3.0, z=0.1), ''),
                       "SpawnModel: model name '%s' is refused: a name may not hold \"::\"" % name)
    assert world_state(api) == before
    frame = api.get_link_state(ROBOT + '::link1', ROBOT + '::link2')
    assert frame.success, frame.status_message
    assert abs(frame.link_state.pose.position.z + 1.0) < 1e-9  # link1 sits 1 m below link2


# --- effort jobs: bounded per joint, the effort limit holds their sum ----------------------------

ROTOR_INERTIA = 0.5
ROTOR_LIMIT = 2.0
ROTOR_URDF = (
    '<robot name="rotor"><link name="world"/><joint name="spin" type="continuous"><parent '
    'link="world"/><child link="rotor"/><origin xyz="0 0 1"/><axis xyz="0 0 1"/><limit effort="%r" '
    'velocity="100"/></joint><link name="rotor"><inertial><mass value="1"/><inertia ixx="1" '
    'ixy="0" ixz="0" iyy="1" iyz="0" izz="%r"/></inertial></link></robot>'
    % (ROTOR_LIMIT, ROTOR_INERTIA))


def test_effort_jobs_are_bounded_per_joint_and_the_limit_holds_their_sum(api):
    assert spawn_urdf(api, 'rotor', ROTOR_URDF).success
    later = ros_time(10 ** 9)
    for _ in range(1000):
        assert api.apply_joint_effort('spin', 0.001, later, ros_duration(-1)).success
    assert_refused(api.apply_joint_effort('spin', 0.001, later, ros_duration(-1)),
                   "ApplyJointEffort: 'rotor::spin' already has 1000 jobs pending, the most it "
                   "takes")
    api.clear_joint_forces('spin')
    # 500 overlapping jobs, each clamped to the limit alone, act as one at the limit.
    for _ in range(500):
        assert api.apply_joint_effort('spin', 3.5, ros_time(0), ros_duration(10 * STEP_NS)).success
    api.run_for(20 * STEP_NS)
    assert abs(api.joint('spin')[1] - ROTOR_LIMIT * 10 * 0.001 / ROTOR_INERTIA) < 1e-9
