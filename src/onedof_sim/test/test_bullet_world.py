"""Unit tests of the pybullet core (onedof_sim.bullet_world), driven step by step without ROS.

The physics figures are checked against closed forms for the tutorial's arm (link2): a compound
pendulum of mass m = 1 with its centre of mass d = 0.5 from the joint and I_yy = 0.1 about it.
"""
import math
import os

import pytest

from onedof_sim.bullet_world import (BulletWorld, GeometryShape, JointType, ModelFormat,
                                     PhysicsParams, Pose, Quat, Twist, Vec3)

URDF_PATH = os.path.join(os.path.dirname(__file__), '..', '..', 'minimal_robot_description',
                         'minimal_robot_description.urdf')
with open(URDF_PATH) as urdf_file:
    TUTORIAL_URDF = urdf_file.read()
ROBOT = 'one_DOF_robot'
MASS, COM_DISTANCE, I_COM = 1.0, 0.5, 0.1
I_PIVOT = I_COM + MASS * COM_DISTANCE ** 2
G = 9.8
MS = 1000000  # ns
# High enough that link2 hangs clear of the ground.
RAISED = Pose(Vec3(0.0, 0.0, 2.0))

# The cafe table of the contract: three static collision boxes.
CAFE_TABLE_SDF = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="cafe_table">
    <static>true</static>
    <link name="link">
      <collision name="surface">
        <pose>0 0 0.755 0 0 0</pose>
        <geometry><box><size>0.913 0.913 0.04</size></box></geometry>
      </collision>
      <collision name="column">
        <pose>0 0 0.37 0 0 0</pose>
        <geometry><box><size>0.042 0.042 0.74</size></box></geometry>
      </collision>
      <collision name="base">
        <pose>0 0 0.02 0 0 0</pose>
        <geometry><box><size>0.56 0.56 0.04</size></box></geometry>
      </collision>
    </link>
  </model>
</sdf>
"""

BOX_SDF = """<sdf version="1.6"><model name="box"><link name="link">
  <inertial><mass>2</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision>
</link></model></sdf>"""


def urdf_with_joint1(extra):
    """The tutorial URDF with `extra` added to joint1 (a limit, a damping)."""
    return TUTORIAL_URDF.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 1 0"/>' + extra)


@pytest.fixture
def world():
    bullet = BulletWorld()
    yield bullet
    bullet.close()


def spawn_robot(world, xml=TUTORIAL_URDF, pose=RAISED, q=None):
    status = world.spawn(ROBOT, xml, ModelFormat.URDF, pose)
    assert status.ok, status.message
    if q is not None:
        assert world.set_model_configuration(ROBOT, ['joint1'], [q]).ok


def joint1(world):
    status, info = world.joint_info('joint1')
    assert status.ok, status.message
    return info


def energy(info):
    """Kinetic plus potential energy of link2, potential measured from the joint's height."""
    return 0.5 * I_PIVOT * info.rate ** 2 + MASS * G * COM_DISTANCE * math.cos(info.position)


def steps_acted_on(world, effort, run_steps):
    """Runs without gravity from rest; the steps an effort acted on, from the rate it left."""
    for _ in range(run_steps):
        world.step()
    return joint1(world).rate * I_PIVOT / (effort * world.params().step)


def set_joint_rate(world, position, rate):
    """joint1 at position and rate: pybullet's reset, the API has no way to set a rate."""
    body = next(b for b in range(world.physics_client.getNumBodies())
                if world.physics_client.getBodyInfo(b)[1].decode() == ROBOT)
    world.physics_client.resetJointState(body, 1, position, rate)


@pytest.fixture
def weightless(world):
    assert world.set_params(PhysicsParams(gravity=Vec3(0, 0, 0))).ok
    spawn_robot(world)
    return world


# --- physics against closed forms -----------------------------------------------------------

def test_small_swing_period_of_the_compound_pendulum(world):
    spawn_robot(world, q=math.pi + 0.05)  # 0.05 rad from hanging straight down
    expected = 2 * math.pi * math.sqrt(I_PIVOT / (MASS * G * COM_DISTANCE))
    crossings = []  # times at which the rate changes sign from + to -
    previous = 0.0
    while len(crossings) < 4:
        world.step()
        rate = joint1(world).rate
        if previous > 0 >= rate:
            crossings.append(world.time())
        previous = rate
        assert world.time() < 10, 'the pendulum does not swing'
    period = (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    assert period == pytest.approx(expected, rel=0.005)


def test_energy_is_kept_over_ten_seconds(world):
    """No damping declared: pybullet's default link and joint damping must be gone."""
    spawn_robot(world, q=1.0)
    initial = energy(joint1(world))
    swing = 2 * MASS * G * COM_DISTANCE  # potential energy between upright and hanging
    worst = 0.0
    while world.time() < 10.0:
        world.step()
        worst = max(worst, abs(energy(joint1(world)) - initial))
    assert worst < 0.01 * swing


def test_declared_damping_is_applied_as_minus_d_qdot(world):
    damping = 0.2
    assert world.set_params(PhysicsParams(gravity=Vec3(0, 0, 0))).ok
    spawn_robot(world, xml=urdf_with_joint1('<dynamics damping="%g"/>' % damping))
    assert world.set_model_state(ROBOT, RAISED, Twist()).ok
    set_joint_rate(world, 0.0, 2.0)
    for _ in range(1000):
        world.step()
    # I qdd = -d qdot: the rate decays as exp(-d t / I).
    assert joint1(world).rate == pytest.approx(2.0 * math.exp(-damping * 1.0 / I_PIVOT), rel=0.01)
    assert joint1(world).has_damping and joint1(world).damping == damping


@pytest.mark.parametrize('angle', [2.0, 1.0, -2.5])
def test_holding_effort_minus_mgd_sin_q_holds_the_angle(world, angle):
    spawn_robot(world, q=angle)
    holding = -MASS * G * COM_DISTANCE * math.sin(angle)
    assert world.apply_joint_effort('joint1', holding, 0, -1).ok
    while world.time() < 2.0:
        world.step()
    assert joint1(world).position == pytest.approx(angle, abs=0.005)


def test_continuous_joint_is_not_wrapped(weightless):
    set_joint_rate(weightless, 0.0, 10.0)
    for _ in range(1000):
        weightless.step()
    assert joint1(weightless).position == pytest.approx(10.0, rel=1e-3)


def test_links_of_one_model_do_not_collide(world):
    """Hanging down, link2's cylinder lies inside link1's collision box."""
    spawn_robot(world, q=math.pi)
    for _ in range(500):
        world.step()
    assert joint1(world).position == pytest.approx(math.pi, abs=1e-6)


def test_a_box_slides_on_the_ground_with_mu_1(world):
    """ODE takes the smaller mu of the two surfaces: min(1, 100) = 1, deceleration g."""
    assert world.spawn('box', BOX_SDF, ModelFormat.SDF, Pose(Vec3(0, 0, 0.1))).ok
    for _ in range(200):  # settle
        world.step()
    _, pose, _ = world.model_state('box')
    assert world.set_model_state('box', pose, Twist(Vec3(1.0, 0, 0))).ok
    for _ in range(50):
        world.step()
    _, _, twist = world.model_state('box')
    assert twist.linear.x == pytest.approx(1.0 - G * 0.05, abs=0.05)


def test_the_table_stops_the_arm(world):
    spawn_robot(world, pose=Pose())
    assert world.spawn('cafe_table', CAFE_TABLE_SDF, ModelFormat.SDF, Pose(Vec3(0.85, 0, 0))).ok
    assert world.apply_joint_effort('joint1', 2.0, 0, -1).ok  # presses towards the table
    while world.time() < 3.0:
        world.step()
    arm = joint1(world)
    # Free, the arm would swing down to the ground (q near pi); the table top, 0.775 high,
    # stops it short of horizontal.
    assert 1.5 < arm.position < 2.3
    assert abs(arm.rate) < 0.01


# --- frames ---------------------------------------------------------------------------------

def test_model_and_link_states_are_link_frames(world):
    spawn_robot(world, pose=Pose(Vec3(0.5, 0.2, 0.0)), q=math.pi / 2)
    _, pose, _ = world.model_state(ROBOT)
    assert tuple(pose.position) == pytest.approx((0.5, 0.2, 0.0))
    # link2's frame sits on the joint, 1 m above the pedestal's base, rotated by q about y.
    _, pose, _ = world.link_state(ROBOT + '::link2')
    assert tuple(pose.position) == pytest.approx((0.5, 0.2, 1.0))
    s = math.sin(math.pi / 4)
    assert tuple(pose.orientation) == pytest.approx((s, 0, s, 0))
    _, pose, _ = world.link_state(ROBOT + '::link2', ROBOT + '::link1')
    assert tuple(pose.position) == pytest.approx((0, 0, 1.0))


def test_link_frame_velocity_is_that_of_its_origin(weightless):
    set_joint_rate(weightless, 0.0, 3.0)
    _, _, twist = weightless.link_state(ROBOT + '::link2')
    # The origin of link2 is on the joint axis: it does not move, the link turns about y.
    assert tuple(twist.linear) == pytest.approx((0, 0, 0), abs=1e-9)
    assert tuple(twist.angular) == pytest.approx((0, 3.0, 0))


def test_free_body_with_offset_inertial_keeps_its_link_frame(world):
    urdf = """<robot name="b"><link name="base"><inertial><origin xyz="0.1 0.2 0.3" rpy="0 0.3 0"/>
      <mass value="2"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3"/>
      </inertial></link></robot>"""
    yaw = 0.6
    spawn = Pose(Vec3(1, 2, 3), Quat(math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)))
    assert world.spawn('b', urdf, ModelFormat.URDF, spawn).ok
    _, pose, _ = world.model_state('b')
    assert tuple(pose.position) == pytest.approx(tuple(spawn.position))
    assert tuple(pose.orientation) == pytest.approx(tuple(spawn.orientation))
    moved = Pose(Vec3(4, 5, 6))
    assert world.set_model_state('b', moved, Twist(angular=Vec3(0, 0, 1.0))).ok
    _, pose, twist = world.model_state('b')
    assert tuple(pose.position) == pytest.approx((4, 5, 6))
    assert tuple(twist.linear) == pytest.approx((0, 0, 0), abs=1e-9)
    world.reset_world()
    _, pose, twist = world.model_state('b')
    assert tuple(pose.position) == pytest.approx(tuple(spawn.position))
    assert tuple(twist.angular) == pytest.approx((0, 0, 0))


def test_table_collision_shapes_in_world(world):
    assert world.spawn('cafe_table', CAFE_TABLE_SDF, ModelFormat.SDF, Pose(Vec3(0.85, 0, 0))).ok
    table = [s for s in world.collision_shapes() if s.model == 'cafe_table']
    assert [s.shape for s in table] == [GeometryShape.BOX] * 3
    surface = table[0]
    assert tuple(surface.size) == pytest.approx((0.913, 0.913, 0.04))
    assert tuple(surface.pose.position) == pytest.approx((0.85, 0, 0.755))
    status, info = world.model_properties('cafe_table')
    assert info.is_static and info.links == ['cafe_table::link']
    assert info.geoms == ['surface', 'column', 'base']


def test_model_properties_of_the_tutorial_robot(world):
    spawn_robot(world)
    status, info = world.model_properties(ROBOT)
    assert status.ok
    assert info.links == [ROBOT + '::link1', ROBOT + '::link2']
    assert info.canonical_link == ROBOT + '::link1'
    assert info.joints == ['glue_robot_to_world', 'joint1']
    status, link = world.link_properties(ROBOT + '::link2')
    assert (link.mass, link.ixx, link.iyy, link.izz) == (1, 0.1, 0.1, 0.005)
    assert tuple(link.com.position) == (0, 0, 0.5)
    info = joint1(world)
    assert (info.type, info.has_damping, info.position, info.rate) == (
        JointType.CONTINUOUS, False, 0.0, 0.0)


# --- effort jobs ----------------------------------------------------------------------------

def test_a_10_ms_job_acts_on_exactly_10_steps(weightless):
    assert weightless.apply_joint_effort('joint1', 1.0, 0, 10 * MS).ok
    assert steps_acted_on(weightless, 1.0, 30) == pytest.approx(10, abs=1e-6)


def test_back_to_back_jobs_do_not_double_the_boundary_step(weightless):
    assert weightless.apply_joint_effort('joint1', 1.0, 0, 10 * MS).ok
    assert weightless.apply_joint_effort('joint1', 1.0, 10 * MS, 10 * MS).ok
    assert steps_acted_on(weightless, 1.0, 30) == pytest.approx(20, abs=1e-6)


def test_overlapping_jobs_sum(weightless):
    assert weightless.apply_joint_effort('joint1', 1.0, 0, 10 * MS).ok
    assert weightless.apply_joint_effort('joint1', 2.0, 5 * MS, 10 * MS).ok
    # 10 steps of 1 plus 10 steps of 2: 30 step-efforts of 1.
    assert steps_acted_on(weightless, 1.0, 30) == pytest.approx(30, abs=1e-6)


def test_a_future_job_waits_and_a_past_start_means_now(weightless):
    for _ in range(5):
        weightless.step()
    assert weightless.apply_joint_effort('joint1', 1.0, 0, 3 * MS).ok  # start 0 is in the past
    assert weightless.apply_joint_effort('joint1', 1.0, 20 * MS, 4 * MS).ok
    assert steps_acted_on(weightless, 1.0, 10) == pytest.approx(3, abs=1e-6)  # to 15 ms
    assert steps_acted_on(weightless, 1.0, 20) == pytest.approx(3 + 4, abs=1e-6)


def test_zero_duration_does_nothing_and_says_so(weightless):
    status = weightless.apply_joint_effort('joint1', 1.0, 0, 0)
    assert status.ok and 'nothing' in status.message
    assert steps_acted_on(weightless, 1.0, 5) == 0


def test_a_job_shorter_than_a_step_acts_on_one_step_and_says_so(weightless):
    status = weightless.apply_joint_effort('joint1', 1.0, 0, MS // 4)
    assert status.ok and 'one step' in status.message
    assert steps_acted_on(weightless, 1.0, 5) == pytest.approx(1, abs=1e-6)


def test_a_forever_job_lasts_until_cleared(weightless):
    assert weightless.apply_joint_effort('joint1', 1.0, 0, -1).ok
    assert steps_acted_on(weightless, 1.0, 50) == pytest.approx(50, abs=1e-6)
    weightless.clear_joint_forces('joint1')
    assert steps_acted_on(weightless, 1.0, 50) == pytest.approx(50, abs=1e-6)


def test_effort_is_clamped_to_the_urdf_limit(world):
    assert world.set_params(PhysicsParams(gravity=Vec3(0, 0, 0))).ok
    spawn_robot(world, xml=urdf_with_joint1('<limit effort="2" velocity="10"/>'))
    status = world.apply_joint_effort('joint1', -5.0, 0, 10 * MS)
    assert status.ok and 'clamped' in status.message
    assert steps_acted_on(world, -2.0, 20) == pytest.approx(10, abs=1e-6)


@pytest.mark.parametrize('effort', [math.nan, math.inf, -math.inf])
def test_non_finite_effort_is_refused(weightless, effort):
    assert not weightless.apply_joint_effort('joint1', effort, 0, -1).ok
    assert steps_acted_on(weightless, 1.0, 5) == 0


def test_reset_drops_jobs_and_restores_the_spawn_state(weightless):
    assert weightless.apply_joint_effort('joint1', 1.0, 0, -1).ok
    for _ in range(100):
        weightless.step()
    weightless.reset_world()
    assert weightless.time_ns() == 100 * MS
    assert (joint1(weightless).position, joint1(weightless).rate) == (0.0, 0.0)
    assert steps_acted_on(weightless, 1.0, 10) == 0
    weightless.reset_simulation()
    assert weightless.time_ns() == 0


def test_delete_model_drops_its_jobs(weightless):
    assert weightless.apply_joint_effort('joint1', 1.0, 0, -1).ok
    assert weightless.delete_model(ROBOT).ok
    assert not weightless.joint_info('joint1')[0].ok
    spawn_robot(weightless)
    assert steps_acted_on(weightless, 1.0, 5) == 0


# --- bad input: a clear error, the world unchanged ------------------------------------------

def snapshot(world):
    return (world.model_names(), world.time_ns(), joint1(world), world.model_state(ROBOT),
            world.params())


@pytest.mark.parametrize('name, xml, model_format, reference, words', [
    (ROBOT, TUTORIAL_URDF, ModelFormat.URDF, '', 'already exists'),
    ('', TUTORIAL_URDF, ModelFormat.URDF, '', 'name is empty'),
    ('r2', '<robot name="r"><link name="a"></robot>', ModelFormat.URDF, '', 'invalid URDF'),
    ('r2', '<sdf/>', ModelFormat.URDF, '', 'invalid URDF'),
    ('r2', TUTORIAL_URDF.replace('"continuous"', '"floating"'), ModelFormat.URDF, '',
     'only revolute, continuous, prismatic and fixed joints are supported'),
    ('r2', TUTORIAL_URDF.replace('parent link="link1"', 'parent link="nowhere"'),
     ModelFormat.URDF, '', "unknown parent link 'nowhere'"),
    ('r2', TUTORIAL_URDF.replace('<mass value="1"/>', '<mass value="-1"/>'), ModelFormat.URDF, '',
     'negative mass'),
    ('r2', TUTORIAL_URDF.replace('<link name="link2">', '<link name="link2"><!--')
     .replace('<visual>\n      <origin xyz="0 0 0.5" rpy="0 0 0"/>\n      <geometry>\n'
              '        <cylinder', '--><visual><geometry><cylinder'), ModelFormat.URDF, '',
     "link 'link2' moves but has no mass"),
    ('r2', TUTORIAL_URDF, ModelFormat.URDF, 'nowhere', "reference frame 'nowhere' not found"),
    ('t2', CAFE_TABLE_SDF.replace('<box>', '<mesh>').replace('</box>', '</mesh>'),
     ModelFormat.SDF, '', 'only box, cylinder and sphere collisions are supported'),
    ('t2', TUTORIAL_URDF, ModelFormat.SDF, '', 'invalid SDF'),
])
def test_bad_spawn_is_refused_and_changes_nothing(world, name, xml, model_format, reference,
                                                  words):
    spawn_robot(world, q=1.0)
    before = snapshot(world)
    status = world.spawn(name, xml, model_format, Pose(), reference)
    assert not status.ok and words in status.message, status.message
    assert status.message.startswith('SpawnModel: ')
    assert snapshot(world) == before


@pytest.mark.parametrize('joints, positions, words', [
    (['joint1'], [1.0, 2.0], 'differ in length'),
    (['joint1', 'nope'], [2.0, 2.0], 'not found'),
    (['joint1'], [math.nan], 'not finite'),
])
def test_bad_configuration_is_refused_and_changes_nothing(world, joints, positions, words):
    spawn_robot(world, q=1.0)
    before = snapshot(world)
    status = world.set_model_configuration(ROBOT, joints, positions)
    assert not status.ok and words in status.message, status.message
    assert snapshot(world) == before


@pytest.mark.parametrize('change', [
    {'step': 0.0}, {'step': -0.001}, {'step': math.nan}, {'erp': math.inf},
    {'gravity': Vec3(0, 0, math.nan)}, {'sor_pgs_iters': -1}])
def test_bad_physics_params_are_refused(world, change):
    spawn_robot(world, q=1.0)
    before = snapshot(world)
    base = PhysicsParams()
    for key, value in change.items():
        setattr(base, key, value)
    assert not world.set_params(base).ok
    assert snapshot(world) == before


def test_unknown_names_are_reported(world):
    spawn_robot(world)
    assert world.joint_info('nope')[0].message == 'GetJointProperties: joint not found'
    assert world.apply_joint_effort('nope', 1, 0, -1).message == (
        'ApplyJointEffort: joint not found')
    assert world.link_state('link2')[0].message == (
        'GetLinkState: link not found, did you forget to scope the link by model name?')
    assert world.model_state('nope')[0].message == 'GetModelState: model does not exist'
    assert world.delete_model('nope').message == 'DeleteModel: model does not exist'
    assert world.apply_joint_effort('glue_robot_to_world', 1, 0, -1).message == (
        "ApplyJointEffort: joint 'glue_robot_to_world' is fixed and takes no effort")
    assert world.set_link_state(ROBOT + '::link1', Pose(), Twist()).message == (
        "SetLinkState: link 'one_DOF_robot::link1' is anchored to the world; move its model "
        "with set_model_state")
    assert not world.model_state(ROBOT, 'nowhere')[0].ok
    assert world.joint_info(ROBOT + '::joint1')[0].ok
    assert not world.joint_info('other::joint1')[0].ok


def test_a_new_step_size_is_used(world):
    spawn_robot(world)
    assert world.set_params(PhysicsParams(step=0.002)).ok
    world.step()
    world.step()
    assert world.time_ns() == 4 * MS and world.step_count() == 2


def test_a_wrench_pushes_a_free_box_by_f_t_over_m(world):
    assert world.set_params(PhysicsParams(gravity=Vec3(0, 0, 0))).ok
    assert world.spawn('box', BOX_SDF, ModelFormat.SDF, Pose(Vec3(0, 0, 1.0))).ok
    status = world.apply_body_wrench('box::link', '', Vec3(), Vec3(1.0, 0, 0), Vec3(), 0,
                                     100 * MS)
    assert status == (True, 'ApplyBodyWrench: wrench set')
    for _ in range(150):
        world.step()
    _, _, twist = world.model_state('box')
    assert twist.linear.x == pytest.approx(1.0 * 0.1 / 2.0, abs=1e-9)  # 1 N for 0.1 s on 2 kg
    # Applied at the world origin, 1 m below the centre: torque (0, -1, 0) on I = 0.1 for 0.1 s.
    assert tuple(twist.angular) == pytest.approx((0, -1.0, 0), abs=1e-9)


def test_only_a_free_root_link_can_be_set(world):
    spawn_robot(world)
    status = world.set_link_state(ROBOT + '::link2', Pose(), Twist())
    assert not status.ok and 'set_model_configuration' in status.message
    assert world.spawn('box', BOX_SDF, ModelFormat.SDF, Pose(Vec3(0, 0, 1.0))).ok
    assert world.set_link_state('box::link', Pose(Vec3(0, 1, 0.5)), Twist()).ok
    _, pose, _ = world.link_state('box::link')
    assert tuple(pose.position) == pytest.approx((0, 1, 0.5))
