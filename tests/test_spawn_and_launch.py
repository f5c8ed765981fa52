"""spawn_model, the model path and the launch files, driven as a student types them against the
real simulator node: the tutorial's spawn commands, the cafe table stopping the arm, spawn_model's
errors and options (-J, -unpause, -wait, -b), GAZEBO_MODEL_PATH, and the launch files."""
import math
import os
import signal
import subprocess

import pytest

from api_client import ROBOT, GazeboApi, pose
from conftest import ENGINES, GROUND, TUTORIAL_URDF, WORKSPACE, start_sim
from onedof_harness.private_ros import wait_until

DESCRIPTION_DIR = os.path.join(WORKSPACE, 'src', 'minimal_robot_description')
PACKAGE_MODELS = os.path.join(WORKSPACE, 'src', 'onedof_sim', 'models')
TUTORIAL_SPAWN_ROBOT = ['-file', 'minimal_robot_description.urdf', '-urdf', '-model', ROBOT]
TUTORIAL_SPAWN_TABLE = ['-database', 'cafe_table', '-sdf', '-model', 'cafe_table', '-x', '0.85']
SPAWNED = 'SpawnModel: Successfully spawned entity'
# What a launch file passes on and what spawn_model checks itself do not depend on the engine:
# those tests run on one, the launch's on the one physics:= has to choose (not the default).
ONE_ENGINE = pytest.mark.parametrize('engine', ENGINES[:1], indirect=True)
CHOSEN_ENGINE = pytest.mark.parametrize('engine', ENGINES[-1:], indirect=True)


def spawn_model(ros, *args, cwd=None, env=None, input=None, timeout=300):
    """Runs `rosrun onedof_sim spawn_model ARGS` to completion, in cwd (default the workspace).
    The timeout only catches a hang: at load 20 a python command gets a twentieth of a core and
    takes a minute and more to start, spawn and exit."""
    return subprocess.run(['rosrun', 'onedof_sim', 'spawn_model'] + list(args),
                          env=dict(ros.env, **(env or {})), cwd=cwd or WORKSPACE, input=input,
                          stdin=subprocess.DEVNULL if input is None else None,
                          capture_output=True, text=True, timeout=timeout)


def start_spawn_model(ros, *args, name='spawn_model'):
    """Starts spawn_model in the background (for -b and -wait); output in ros.log_text(name)."""
    return ros.start(['rosrun', 'onedof_sim', 'spawn_model'] + list(args), name=name)


def succeeded(result):
    return '%s\nstdout:\n%s\nstderr:\n%s' % (result.args, result.stdout, result.stderr)


def tutorial_urdf():
    with open(TUTORIAL_URDF) as f:
        return f.read()


# --- the launch files -------------------------------------------------------------------------

def test_launch_with_sim_false_only_loads_the_urdf(ros):
    launch = ['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch',
              'sim:=false']
    nodes = ros.run(launch[:1] + ['--nodes'] + launch[1:])
    assert nodes.returncode == 0 and nodes.stdout.strip() == '', succeeded(nodes)

    ros.start(launch, name='roslaunch')

    def description():
        code, _, value = ros.master().getParam('/private_ros', '/robot_description')
        return value if code == 1 else None
    assert wait_until(description, 60, what='/robot_description') == tutorial_urdf()


@CHOSEN_ENGINE
def test_launch_starts_the_sim_and_spawns_the_robot(ros, rospy_client, engine):
    launch = ['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch',
              'physics:=' + engine]
    nodes = ros.run(launch[:1] + ['--nodes'] + launch[1:])
    assert sorted(nodes.stdout.split()) == ['/gazebo', '/spawn_one_DOF_robot'], succeeded(nodes)

    roslaunch = ros.start(launch, name='roslaunch')
    api = GazeboApi(rospy_client)
    wait_until(lambda: roslaunch.poll() is not None or api.get_model_state(ROBOT, '').success, 60,
               what='%s to be spawned' % ROBOT)
    assert roslaunch.poll() is None, ros.log_text(roslaunch)
    assert '(engine: %s)' % engine in api.get_physics_properties().status_message
    assert rospy_client.get_param('/use_sim_time') is True
    assert rospy_client.get_param('/robot_description') == tutorial_urdf()

    result = ros.run(['rosservice', 'call', '/gazebo/get_joint_properties', 'joint1'])
    assert result.returncode == 0, succeeded(result)
    assert 'success: True' in result.stdout
    assert 'status_message: "GetJointProperties: got properties"' in result.stdout


@CHOSEN_ENGINE
def test_launch_passes_paused_to_the_sim(ros, rospy_client, engine):
    ros.start(['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch',
               'paused:=true', 'physics:=' + engine], name='roslaunch')
    api = GazeboApi(rospy_client)
    wait_until(lambda: api.get_model_state(ROBOT, '').success, 60, what='%s to be spawned' % ROBOT)
    physics = api.get_physics_properties()
    assert physics.pause is True
    assert api.get_world_properties().sim_time == 0.0


def test_malformed_urdf_stops_the_launch_naming_the_file(ros, tmp_path):
    bad = tmp_path / 'bad.urdf'
    bad.write_text('<robot name="bad"><link name="a"></robot>')
    result = ros.run(['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch',
                      'model:=%s' % bad])
    assert result.returncode != 0, succeeded(result)
    output = result.stdout + result.stderr
    assert "malformed URDF '%s'" % bad in output, output
    assert not ros.master().lookupNode('/private_ros', '/gazebo')[0] == 1


def test_unknown_physics_engine_stops_the_simulator_naming_the_known_ones(ros):
    result = ros.run(['roslaunch', 'onedof_sim', 'empty_world.launch', 'physics:=havok'])
    output = result.stdout + result.stderr
    # The node refuses the engine and exits; roslaunch ends with its last process.
    assert 'all processes on machine have died' in output, succeeded(result)
    assert 'havok' in output, succeeded(result)
    for engine in ENGINES:
        assert engine in output, succeeded(result)


# --- the tutorial's spawn commands --------------------------------------------------------------

def test_tutorial_spawn_command_as_typed(ros, running_sim, rospy_client):
    # cd src/minimal_robot_description; rosrun onedof_sim spawn_model -file ... (relative path)
    result = spawn_model(ros, *TUTORIAL_SPAWN_ROBOT, cwd=DESCRIPTION_DIR)
    assert result.returncode == 0, succeeded(result)
    assert 'waiting for service /gazebo/spawn_urdf_model' in result.stdout
    assert SPAWNED in result.stdout
    api = GazeboApi(rospy_client)
    assert api.get_model_state(ROBOT, '').success
    properties = api.get_joint_properties('joint1')
    assert properties.success and properties.position == (0.0,)


def link_rectangle(q, joint=(0.0, 1.0), length=1.0, radius=0.1):
    """Corners (x, z) of link2's cylinder cut by the plane y = 0 at joint angle q.

    The cylinder's axis lies in that plane, so this rectangle is also the cylinder's projection
    onto it; the table top spans far more than the cylinder in y, so the two bodies touch exactly
    when this rectangle touches the table top's cross-section.
    """
    along = (math.sin(q), math.cos(q))  # q = 0 points up; positive q tips toward +x
    across = (math.cos(q), -math.sin(q))
    return [(joint[0] + s * along[0] + t * across[0], joint[1] + s * along[1] + t * across[1])
            for s, t in ((0, -radius), (length, -radius), (length, radius), (0, radius))]


def table_top_rectangle(table_x, half_size=0.913 / 2, top=0.775, thickness=0.04):
    return [(table_x - half_size, top - thickness), (table_x + half_size, top - thickness),
            (table_x + half_size, top), (table_x - half_size, top)]


def rectangles_overlap(a, b):
    """Separating-axis test of two convex polygons given as corner lists."""
    for polygon in (a, b):
        for i in range(len(polygon)):
            (x0, z0), (x1, z1) = polygon[i], polygon[(i + 1) % len(polygon)]
            axis = (z0 - z1, x1 - x0)
            pa = [axis[0] * x + axis[1] * z for x, z in a]
            pb = [axis[0] * x + axis[1] * z for x, z in b]
            if max(pa) < min(pb) or max(pb) < min(pa):
                return False
    return True


def first_contact_angle(table_x):
    """The smallest q > 0 at which link2 touches the table top: scan, then bisect."""
    top = table_top_rectangle(table_x)
    q = 0.0
    while not rectangles_overlap(link_rectangle(q + 0.01), top):
        q += 0.01
        assert q < math.pi, 'the link never reaches the table'
    low, high = q, q + 0.01
    while high - low > 1e-9:
        middle = (low + high) / 2
        low, high = (low, middle) if rectangles_overlap(link_rectangle(middle), top) else (middle, high)
    return high


def test_contact_geometry_is_the_tip_rim_on_the_top_face():
    # Cross-check of the numeric search: the tip's lower rim corner (1, -0.1) in link coordinates
    # reaches the top face z = 0.775 where cos q - 0.1 sin q = -0.225, well inside the top in x.
    analytic = math.acos(-0.225 / math.hypot(1, 0.1)) - math.atan(0.1)
    assert first_contact_angle(0.85) == pytest.approx(analytic, abs=1e-6)
    assert 0.3935 < math.sin(analytic) + 0.1 * math.cos(analytic) < 1.3065


def test_cafe_table_stops_the_link_on_its_top(ros, running_sim, rospy_client):
    api = GazeboApi(rospy_client)
    robot = spawn_model(ros, *TUTORIAL_SPAWN_ROBOT, cwd=DESCRIPTION_DIR)
    assert robot.returncode == 0, succeeded(robot)
    table = spawn_model(ros, *TUTORIAL_SPAWN_TABLE)  # the arm is upright: q = 0
    assert table.returncode == 0, succeeded(table)
    assert 'waiting for service /gazebo/spawn_sdf_model' in table.stdout and SPAWNED in table.stdout

    state = api.get_model_state('cafe_table', '')
    assert state.success
    assert (state.pose.position.x, state.pose.position.y, state.pose.position.z) == pytest.approx(
        (0.85, 0.0, 0.0), abs=1e-9)
    assert api.get_model_properties('cafe_table').is_static

    # Push the link toward the table (q positive, +x) until the test ends.
    start = api.get_world_properties().sim_time
    pushed = api.apply_joint_effort('joint1', 2.0, rospy_client.Time(0), rospy_client.Duration(-1))
    assert pushed.success, pushed.status_message
    wait_until(lambda: api.get_world_properties().sim_time > start + 4.0, 120,
               what='4 s of sim time')
    first, _ = api.joint()
    wait_until(lambda: api.get_world_properties().sim_time > start + 5.0, 120,
               what='5 s of sim time')
    position, rate = api.joint()

    expected = first_contact_angle(0.85)  # 1.697 rad: the tip's rim on the top face
    assert position == pytest.approx(expected, abs=0.02)
    assert abs(position - first) < 0.005 and abs(rate) < 0.05, 'the link is not at rest'


# --- spawn_model's errors -----------------------------------------------------------------------

@ONE_ENGINE
def test_spawn_model_errors_exit_non_zero_and_leave_the_sim_running(ros, running_sim,
                                                                   rospy_client):
    api = GazeboApi(rospy_client)
    first = spawn_model(ros, *TUTORIAL_SPAWN_ROBOT, cwd=DESCRIPTION_DIR)
    assert first.returncode == 0, succeeded(first)
    # The message the simulator gives for a duplicate, to find it in spawn_model's output.
    duplicate = api.spawn_urdf_model(ROBOT, tutorial_urdf(), '', api.get_model_state(ROBOT, '').pose, '')
    assert not duplicate.success and duplicate.status_message

    cases = [
        (['-file', TUTORIAL_URDF, '-urdf'], 'the following arguments are required: -model'),
        (['-file', TUTORIAL_URDF, '-urdf', '-sdf', '-model', 'x'],
         'argument -sdf: not allowed with argument -urdf'),
        (['-file', TUTORIAL_URDF, '-urdf', '-model', 'x', '-frobnicate'],
         'unrecognized arguments: -frobnicate'),
        (['-file', 'no_such.urdf', '-urdf', '-model', 'x'],
         'file no_such.urdf does not exist (looked for %s)' % os.path.join(WORKSPACE, 'no_such.urdf')),
        (['-database', 'no_such_model', '-sdf', '-model', 'x'],
         "model 'no_such_model' not found in the model path: no no_such_model/model.sdf in %s"
         % PACKAGE_MODELS),
        (['-param', 'no_such_param', '-urdf', '-model', 'x'], 'parameter /no_such_param does not exist'),
        (['-file', TUTORIAL_URDF, '-urdf', '-model', ROBOT],
         'spawning %s failed: %s' % (ROBOT, duplicate.status_message)),
    ]
    for args, message in cases:
        result = spawn_model(ros, *args)
        assert result.returncode != 0, succeeded(result)
        assert 'spawn_model: error: ' + message in result.stderr, succeeded(result)
        assert api.get_world_properties().model_names == [GROUND, ROBOT]


def test_model_the_simulator_refuses_is_reported(ros, running_sim, rospy_client):
    # Well-formed XML, but not a model: the simulator's reason is printed.
    result = spawn_model(ros, '-stdin', '-sdf', '-model', 'nothing',
                         input='<sdf version="1.6"><world name="w"/></sdf>')
    assert result.returncode != 0, succeeded(result)
    assert 'spawn_model: error: spawning nothing failed: ' in result.stderr
    assert result.stderr.strip().split('failed: ', 1)[1], 'no reason given'
    assert GazeboApi(rospy_client).get_world_properties().model_names == [GROUND]


# The book's exmpl_models cylinder (learning_ros: cylinder/model-1_4.sdf), reproduced: 10 kg with
# moments of 0.01 kg m^2. Its <cylinder> gives radius and length as attributes, which SDF does
# not define: libsdformat (Gazebo's as ours) warns and takes SDF's defaults, a cylinder 2 m across
# and 1 m long, for which those moments are some 300 times too small.
BOOK_CYLINDER_SDF = """<?xml version='1.0'?>
<sdf version='1.4'>
  <model name="cylinder">
    <link name='link'>
      <pose>0.0 0 0.0 0 0 0</pose>
      <inertial>
        <mass>10</mass>
        <inertia>
          <ixx>0.01</ixx>
          <ixy>0</ixy>
          <ixz>0</ixz>
          <iyy>0.01</iyy>
          <iyz>0</iyz>
          <izz>0.01</izz>
        </inertia>
      </inertial>
      <collision name='collision'>
        <geometry>
          <cylinder length="0.2" radius="0.5"/>
        </geometry>
        <surface>
          <friction>
            <ode>
              <mu>50.0</mu>
              <mu2>50.0</mu2>
            </ode>
          </friction>
          <contact>
            <ode>
              <kp>1000000.0</kp>
              <kd>100.0</kd>
              <max_vel>1.0</max_vel>
              <min_depth>0.0005</min_depth>
            </ode>
          </contact>
        </surface>
      </collision>
      <visual name='visual'>
        <geometry>
          <cylinder length="0.2" radius="0.5"/>
        </geometry>
        <material>
          <ambient>1 0 0 1</ambient>
          <diffuse>1 0 0 1</diffuse>
        </material>
      </visual>
    </link>
  </model>
</sdf>
"""


def test_the_books_thin_cylinder_spawns_with_a_warning_falls_and_rests(ros, shared_sim,
                                                                       tmp_path):
    """As the book's add_cylinder.launch spawns it: Gazebo spawns it, and so does the simulator,
    warning that its inertia is implausible. It falls from 4 m and comes to rest on an end face
    on the ground, the world stepping finite values throughout. Its implausible inertia shows:
    on ODE it creeps by a millimetre or two a second as it rests."""
    model = tmp_path / 'model-1_4.sdf'
    model.write_text(BOOK_CYLINDER_SDF)
    result = spawn_model(ros, '-file', str(model), '-sdf', '-model', 'cylinder', '-x', '2.5',
                         '-y', '0', '-z', '4')
    assert result.returncode == 0, succeeded(result)
    output = result.stdout + result.stderr
    assert SPAWNED + "; warning: link 'link' (with the links welded to it) has a smallest " \
        "principal moment of inertia of 0.01 kg m^2, implausibly small for its collision " \
        "shape (realistic: at least " in output, succeeded(result)
    api = shared_sim
    api.run_for(3 * 10 ** 9)
    landed = api.get_model_state('cylinder', '')
    api.run_for(10 ** 9)
    rested = api.get_model_state('cylinder', '')
    for state in (landed, rested):
        position, orientation = state.pose.position, state.pose.orientation
        values = (position.x, position.y, position.z, state.twist.linear.x,
                  state.twist.linear.y, state.twist.linear.z, state.twist.angular.x,
                  state.twist.angular.y, state.twist.angular.z)
        assert all(math.isfinite(v) for v in values), state
        # On an end face: 0.5 m up (half its length), its axis vertical (either way up).
        assert position.z == pytest.approx(0.5, abs=5e-3), state
        axis_z = 1 - 2 * (orientation.x ** 2 + orientation.y ** 2)
        assert abs(axis_z) == pytest.approx(1, abs=1e-3), state
        assert math.hypot(position.x - 2.5, position.y) < 2, state
        assert all(abs(v) < 0.05 for v in values[3:]), state
    moved = math.hypot(rested.pose.position.x - landed.pose.position.x,
                       rested.pose.position.y - landed.pose.position.y)
    assert moved < 0.01, (landed, rested)


# --- -J, -unpause, -wait, -b ----------------------------------------------------------------------

def test_joint_positions_are_set_and_physics_stays_paused(ros, shared_sim):
    api = shared_sim  # paused, as a simulator started with -u
    result = spawn_model(ros, *TUTORIAL_SPAWN_ROBOT, '-J', 'joint1', '0.5', cwd=DESCRIPTION_DIR)
    assert result.returncode == 0, succeeded(result)
    assert 'SetModelConfiguration: success' in result.stdout
    assert api.joint() == pytest.approx((0.5, 0.0), abs=1e-9)
    assert api.get_physics_properties().pause is True

    unknown = spawn_model(ros, *TUTORIAL_SPAWN_TABLE, '-model', 'table2', '-J', 'no_joint', '1')
    assert unknown.returncode != 0, succeeded(unknown)
    assert 'spawn_model: error: setting joints no_joint of table2 failed: ' in unknown.stderr


def test_unpause_starts_physics_after_spawning(ros, shared_sim):
    api = shared_sim  # paused, as a simulator started with -u
    result = spawn_model(ros, *TUTORIAL_SPAWN_TABLE, '-unpause')
    assert result.returncode == 0, succeeded(result)
    assert api.get_physics_properties().pause is False
    wait_until(lambda: api.get_world_properties().sim_time > 0.1, 60, what='sim time to advance')


def test_wait_spawns_only_after_the_awaited_model_exists(ros, running_sim, rospy_client):
    api = GazeboApi(rospy_client)
    waiting = start_spawn_model(ros, *TUTORIAL_SPAWN_TABLE, '-wait', ROBOT)
    wait_until(lambda: 'waiting for model %s' % ROBOT in ros.log_text(waiting), 60,
               what='spawn_model to wait for %s' % ROBOT)
    assert waiting.poll() is None and 'cafe_table' not in api.get_world_properties().model_names

    robot = spawn_model(ros, *TUTORIAL_SPAWN_ROBOT, cwd=DESCRIPTION_DIR)
    assert robot.returncode == 0, succeeded(robot)
    assert waiting.wait(timeout=300) == 0, ros.log_text(waiting)
    assert api.get_world_properties().model_names == [GROUND, ROBOT, 'cafe_table']


def test_bond_deletes_the_model_when_spawn_model_is_stopped(ros, running_sim, rospy_client):
    api = GazeboApi(rospy_client)
    bonded = start_spawn_model(ros, *TUTORIAL_SPAWN_TABLE, '-b')
    wait_until(lambda: bonded.poll() is not None or 'holding cafe_table' in ros.log_text(bonded), 60,
               what='spawn_model -b to hold the table')
    assert bonded.poll() is None, ros.log_text(bonded)
    assert api.get_world_properties().model_names == [GROUND, 'cafe_table']

    os.killpg(bonded.pid, signal.SIGINT)  # Ctrl-C
    assert bonded.wait(timeout=300) == 0, ros.log_text(bonded)
    assert 'DeleteModel: successfully deleted model' in ros.log_text(bonded)
    assert api.get_world_properties().model_names == [GROUND]


# --- the model path ---------------------------------------------------------------------------------

BOX_MODEL = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="test_box">
    <static>true</static>
    <link name="link">
      <collision name="box"><geometry><box><size>0.3 0.3 0.3</size></box></geometry></collision>
    </link>
  </model>
</sdf>
"""


def model_path_param(ros):
    code, _, value = ros.master().getParam('/test', '/gazebo/model_path')
    return value if code == 1 else None


def restart_sim(ros, sim, engine, env):
    """Stops sim and starts another simulator once the first has left the graph."""
    ros.terminate(sim)
    wait_until(lambda: not ros.has_service('/gazebo/unpause_physics'), 60,
               what='the stopped simulator to leave the graph')
    return start_sim(ros, engine, env=env)


def test_model_path_is_the_package_models_then_gazebo_model_path(ros):
    """The simulator says where model://NAME resolves in its parameter ~model_path: this package's
    models first (the tutorial always gets the models the simulator was built for), then the
    folders of its GAZEBO_MODEL_PATH, empty entries and repeats left out."""
    sim = start_sim(ros, env={'GAZEBO_MODEL_PATH': '/a::/b:%s:/a' % PACKAGE_MODELS})
    assert model_path_param(ros) == [PACKAGE_MODELS, '/a', '/b']
    restart_sim(ros, sim, ENGINES[0], env={'GAZEBO_MODEL_PATH': ''})
    assert model_path_param(ros) == [PACKAGE_MODELS]


@ONE_ENGINE
def test_gazebo_model_path_folders_are_searched(ros, rospy_client, engine, tmp_path):
    """-database searches the model path of the simulator it spawns into: its GAZEBO_MODEL_PATH,
    not spawn_model's."""
    empty, models = tmp_path / 'empty', tmp_path / 'models'
    (models / 'test_box').mkdir(parents=True)
    (models / 'test_box' / 'model.sdf').write_text(BOX_MODEL)
    empty.mkdir()
    path = '%s:%s' % (empty, models)

    unset = start_sim(ros, engine, env={'GAZEBO_MODEL_PATH': ''})
    unset_result = spawn_model(ros, '-database', 'test_box', '-sdf', '-model', 'box1',
                               env={'GAZEBO_MODEL_PATH': path})
    assert unset_result.returncode != 0, succeeded(unset_result)
    assert 'in %s (' % PACKAGE_MODELS in unset_result.stderr, succeeded(unset_result)

    restart_sim(ros, unset, engine, env={'GAZEBO_MODEL_PATH': path})
    result = spawn_model(ros, '-database', 'test_box', '-sdf', '-model', 'box1', '-x', '2', '-z', '0.15',
                         env={'GAZEBO_MODEL_PATH': ''})
    assert result.returncode == 0, succeeded(result)
    state = GazeboApi(rospy_client).get_model_state('box1', '')
    assert state.success and state.pose.position.x == pytest.approx(2.0)

    missing = spawn_model(ros, '-database', 'other_box', '-sdf', '-model', 'box2')
    assert missing.returncode != 0
    assert 'in %s, %s, %s (' % (PACKAGE_MODELS, empty, models) in missing.stderr, succeeded(missing)

    # A simulator that does not say where its models are: -database has nothing to search.
    ros.master().deleteParam('/test', '/gazebo/model_path')
    unsaid = spawn_model(ros, '-database', 'test_box', '-sdf', '-model', 'box3')
    assert unsaid.returncode != 0
    assert ('spawn_model: error: parameter /gazebo/model_path does not exist: the simulator in '
            '/gazebo does not say where its models are' in unsaid.stderr), succeeded(unsaid)


def test_the_ground_is_the_ground_plane_model_listed_deletable_and_spawned_again(
        ros, running_sim, rospy_client):
    """As in Gazebo, the ground is the ground_plane model that the default world places: static,
    listed by get_world_properties and /gazebo/model_states; a box dropped on it comes to rest at
    z = 0. Deleted, nothing holds the box, which falls. Spawned again (spawn_model -database
    ground_plane), it holds a box at z = 0 once more."""
    from gazebo_msgs.msg import ModelStates
    api = GazeboApi(rospy_client)

    def box_after_drop(seconds):
        api.spawn_box(initial_pose=pose(z=0.5))
        start = api.get_world_properties().sim_time
        wait_until(lambda: api.get_world_properties().sim_time > start + seconds, 120,
                   what='%g s of sim time' % seconds)
        state = api.get_model_state('box', '')
        assert api.delete_model('box').success
        return state

    assert api.get_world_properties().model_names == [GROUND]
    assert GROUND in rospy_client.wait_for_message('/gazebo/model_states', ModelStates,
                                                   timeout=60).name
    assert api.get_model_properties(GROUND).is_static
    state = box_after_drop(1.5)
    assert state.pose.position.z == pytest.approx(0.1, abs=0.005)
    assert math.hypot(state.pose.position.x, state.pose.position.y) < 0.001
    assert abs(state.twist.linear.z) < 0.01

    deleted = api.delete_model(GROUND)
    assert deleted.success, deleted.status_message
    assert api.get_world_properties().model_names == []
    state = box_after_drop(1.0)
    # Free fall from 0.5 m for about a second: well below where the ground was, and falling.
    assert state.pose.position.z < -2 and state.twist.linear.z < -5, state

    result = spawn_model(ros, '-database', 'ground_plane', '-sdf', '-model', GROUND)
    assert result.returncode == 0, succeeded(result)
    assert api.get_world_properties().model_names == [GROUND]
    state = box_after_drop(1.5)
    assert state.pose.position.z == pytest.approx(0.1, abs=0.005)
    assert abs(state.twist.linear.z) < 0.01
