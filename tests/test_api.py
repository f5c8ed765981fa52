"""End-to-end tests of the simulator node's Gazebo API (gazebo-api.md), over a real roscore.

Most tests run on the module's simulator of each engine (conftest's shared_sim), which starts each
test as a fresh `-u` node would be: paused at sim time 0, no models, the start-up physics. They
drive it through its ROS services and topics with rospy or the rosservice CLI and check what comes
back; tests that need exact sim times run the paused world for known sim intervals. Tests of
start-up itself (parameters, /use_sim_time) start their own roscore and simulator; the node as a
process (its log, SIGINT) is in test_node_process.py.
"""
import math
import subprocess

import pytest

from api_client import (BOX_SDF, FOREVER_NS, ROBOT, SERVICE_TYPES, STEP_NS, GazeboApi, pendulum_period,
                        pose, ros_duration, ros_time, tutorial_urdf)
from conftest import start_sim
from onedof_harness.private_ros import COMMAND_TIMEOUT, wait_until
from onedof_sim.tutorial import physics

# Noetic's gazebo_msgs (gazebo_ros_pkgs noetic-devel), every type: the sums genmsg computes from
# its definitions (cross-checked against the sums in code generated from the real package).
NOETIC_GAZEBO_MSGS_MD5 = {
    'ContactState': ('rosmsg', '48c0ffb054b8c444f870cecea1ee50d9'),
    'ContactsState': ('rosmsg', 'acbcb1601a8e525bf72509f18e6f668d'),
    'LinkState': ('rosmsg', '0818ebbf28ce3a08d48ab1eaa7309ebe'),
    'LinkStates': ('rosmsg', '48c080191eb15c41858319b4d8a609c2'),
    'ModelState': ('rosmsg', '9330fd35f2fcd82d457e54bd54e10593'),
    'ModelStates': ('rosmsg', '48c080191eb15c41858319b4d8a609c2'),
    'ODEJointProperties': ('rosmsg', '1b744c32a920af979f53afe2f9c3511f'),
    'ODEPhysics': ('rosmsg', '667d56ddbd547918c32d1934503dc335'),
    'PerformanceMetrics': ('rosmsg', '884f71fd5037b886ec5e126b83c4425a'),
    'SensorPerformanceMetric': ('rosmsg', '01762ded18cfe9ebc7c8222667c99547'),
    'WorldState': ('rosmsg', 'de1a9de3ab7ba97ac0e9ec01a4eb481e'),
    'ApplyBodyWrench': ('rossrv', '585b9f9618aa0581b207e2f2d90866bc'),
    'ApplyJointEffort': ('rossrv', 'c0039811b8cc919490b3cff748cdf46b'),
    'BodyRequest': ('rossrv', '5eade9afe7f232d78005bd0cafeab755'),
    'DeleteLight': ('rossrv', 'ae11ea8100d536d5b92c2b5917abf912'),
    'DeleteModel': ('rossrv', '9ce56b4e9e54616de25d796dc972a262'),
    'GetJointProperties': ('rossrv', '7b30be900f50aa21efec4a0ec92d91c9'),
    'GetLightProperties': ('rossrv', 'df2cef87e13e2e6990e81e8aaa454c19'),
    'GetLinkProperties': ('rossrv', '0e06a70386d0ee3fb880c02f23fcd821'),
    'GetLinkState': ('rossrv', '09d6c98cce97b35f7ab9bd70300657ab'),
    'GetModelProperties': ('rossrv', '5717f7bd34ed990fa80e28b3015027a3'),
    'GetModelState': ('rossrv', '4c515e936d3319c9610c559c60bfc3d4'),
    'GetPhysicsProperties': ('rossrv', '575a5e74786981b7df2e3afc567693a6'),
    'GetWorldProperties': ('rossrv', '36bb0f2eccf4d8be971410c22818ba3f'),
    'JointRequest': ('rossrv', '0be1351618e1dc030eb7959d9a4902de'),
    'SetJointProperties': ('rossrv', '15a76e921b1410c698d82782ea5fa370'),
    'SetJointTrajectory': ('rossrv', '88f5c10979e3f9649d5ae87a3b12aa65'),
    'SetLightProperties': ('rossrv', 'e6f13430c57278bb364aca53a1bf5ebf'),
    'SetLinkProperties': ('rossrv', 'd534ce1b36ee99de0ffa806c3a6348f0'),
    'SetLinkState': ('rossrv', '8a5146eb66ae4d26b0860b08f3f271be'),
    'SetModelConfiguration': ('rossrv', '10e3139d3b669c40afc057d38956fff7'),
    'SetModelState': ('rossrv', '5b3ab0281d4f5445def017e3a2e4a07b'),
    'SetPhysicsProperties': ('rossrv', '97e2057080558ce4730434b5fae75c91'),
    'SpawnModel': ('rossrv', '9ed9c82c96abe1a00c3e8cdaeee24413'),
}

EFFORT_SET = 'ApplyJointEffort: effort set'


@pytest.fixture
def api(rospy_client):
    return GazeboApi(rospy_client)


def test_md5_sums_match_noetic_gazebo_msgs(ros):
    # What `rosmsg md5` / `rossrv md5` print, computed in this process (a CLI run per type
    # costs a Python start-up each); the CLI itself is run once below.
    import rosmsg
    modes = {'rosmsg': rosmsg.MODE_MSG, 'rossrv': rosmsg.MODE_SRV}
    wrong = ['gazebo_msgs/%s: %s' % (name, got) for name, (tool, md5) in
             sorted(NOETIC_GAZEBO_MSGS_MD5.items())
             for got in [rosmsg.rosmsg_md5(modes[tool], 'gazebo_msgs/' + name)] if got != md5]
    assert not wrong, '\n'.join(wrong)
    assert ros.run(['rossrv', 'md5', 'gazebo_msgs/SpawnModel']).stdout.strip() == (
        NOETIC_GAZEBO_MSGS_MD5['SpawnModel'][1])
    assert ros.run(['rossrv', 'md5', 'std_srvs/Empty']).stdout.strip() == (
        'd41d8cd98f00b204e9800998ecf8427e')


def test_rosmsg_show_prints_gazebo_msgs_fields(ros):
    out = ros.run(['rosmsg', 'show', 'gazebo_msgs/ModelState'])
    assert out.returncode == 0, out.stderr
    fields = [line for line in out.stdout.splitlines() if line and not line.startswith(' ')]
    assert fields == ['string model_name', 'geometry_msgs/Pose pose',
                      'geometry_msgs/Twist twist', 'string reference_frame']


def test_services_and_topics_have_gazebo_msgs_type_names(ros, shared_sim, api):
    # What `rosservice type` / `rostopic type` print, asked in this process (a CLI run per name
    # costs a Python start-up each); the CLI itself is run once per kind below.
    import rosservice
    import rostopic
    api.unpause_physics()
    for service, type_name in sorted(SERVICE_TYPES.items()):
        package = 'std_srvs' if type_name == 'Empty' else 'gazebo_msgs'
        full_name = type_name if '/' in type_name else package + '/' + type_name
        assert rosservice.get_service_type('/gazebo/' + service) == full_name
    out = ros.run(['rosservice', 'type', '/gazebo/get_joint_properties'])
    assert out.stdout.strip() == 'gazebo_msgs/GetJointProperties', out.stderr
    api.spawn_robot()
    for topic, type_name in (('model_states', 'ModelStates'), ('link_states', 'LinkStates'),
                             ('set_model_state', 'ModelState'), ('set_link_state', 'LinkState')):
        assert rostopic.get_topic_type('/gazebo/' + topic)[0] == 'gazebo_msgs/' + type_name
    out = ros.run(['rostopic', 'type', '/gazebo/model_states'])
    assert out.stdout.strip() == 'gazebo_msgs/ModelStates', out.stderr


# --- the tutorial's commands -----------------------------------------------------------------

def test_rosservice_get_joint_properties_prints_tutorial_lines(ros, shared_sim, api):
    api.spawn_robot()
    out = ros.run(['rosservice', 'call', '/gazebo/get_joint_properties', 'joint1'])
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == [
        'type: 0', 'damping: []', 'position: [0.0]', 'rate: [0.0]', 'success: True',
        'status_message: "GetJointProperties: got properties"']


def test_all_services_and_clock_are_listed(ros, shared_sim):
    shared_sim.unpause_physics()
    services = ros.run(['rosservice', 'list']).stdout.split()
    for name in ('get_joint_properties', 'apply_joint_effort', 'clear_joint_forces',
                 'apply_body_wrench', 'clear_body_wrenches', 'spawn_urdf_model', 'spawn_sdf_model',
                 'delete_model', 'get_model_state', 'set_model_state', 'get_link_state',
                 'set_link_state', 'set_model_configuration', 'get_model_properties',
                 'get_world_properties', 'get_link_properties', 'get_physics_properties',
                 'set_physics_properties', 'pause_physics', 'unpause_physics',
                 'reset_simulation', 'reset_world', 'set_parameters'):
        assert '/gazebo/' + name in services
    wait_until(lambda: '/clock' in ros.run(['rostopic', 'list']).stdout.split(), 30,
               what='/clock in rostopic list')


def test_upright_link_balances_exactly_and_falls_once_tipped(shared_sim, api):
    # The tutorial prints position [0.0] right after spawning into a running simulator: exactly
    # upright, gravity has no lever arm. Tipped a milliradian, the unstable pose gives way.
    api.set_physics(max_update_rate=0.0)
    api.unpause_physics()
    api.spawn_robot()
    spawned = api.sim_time_ns()
    wait_until(lambda: api.sim_time_ns() > spawned + 10 ** 9, 60, what='1 s of sim time')
    assert api.joint() == (0.0, 0.0)
    assert api.set_model_configuration(ROBOT, '', ['joint1'], [0.001]).success
    wait_until(lambda: api.joint()[0] > 1.0, 120, what='link2 to fall from nearly upright')


# --- physics through the API vs closed form --------------------------------------------------

def paused_samples(api, until_ns, steps=10):
    """Exact (sim time, q) samples every `steps` steps: each is read while paused, then the world
    takes exactly that many steps (step_simulation), however busy the machine."""
    samples = []
    api.pause_physics()
    while True:
        now = api.sim_time_ns()
        samples.append((now * 1e-9, api.joint()[0]))
        if now >= until_ns:
            return samples
        reply = api.step_simulation(steps)
        assert reply.success, reply.status_message


def zero_crossings(samples, level):
    crossings = []
    for (t0, q0), (t1, q1) in zip(samples, samples[1:]):
        if (q0 - level) * (q1 - level) < 0:
            crossings.append(t0 + (t1 - t0) * (level - q0) / (q1 - q0))
    return crossings


def test_small_swing_period_matches_closed_form(shared_sim, api):
    api.spawn_robot(initial_pose=pose(z=1.0))  # hanging down, link2 would touch the ground
    amplitude = 0.05
    res = api.set_model_configuration(ROBOT, '', ['joint1'], [math.pi + amplitude])
    assert res.success, res.status_message
    samples = paused_samples(api, api.sim_time_ns() + int(4.5 * 1e9))
    crossings = zero_crossings(samples, math.pi)
    assert len(crossings) >= 4, crossings
    # Crossings alternate direction; consecutive ones are half a period apart.
    period = 2 * (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    assert period == pytest.approx(pendulum_period(amplitude), rel=0.005)


def test_constant_effort_holds_link_at_balance(shared_sim, api):
    api.spawn_robot()
    balance = 2.5  # on the stable side of the horizontal
    effort = -physics.MASS * physics.GRAVITY * physics.COM_DISTANCE * math.sin(balance)
    assert api.set_model_configuration(ROBOT, '', ['joint1'], [balance]).success
    res = api.apply_joint_effort('joint1', effort, ros_time(0), ros_duration(FOREVER_NS))
    assert res.success, res.status_message
    api.unpause_physics()
    start = api.sim_time_ns()
    positions = []
    while api.sim_time_ns() < start + 2 * 10 ** 9:
        positions.append(api.joint()[0])
    assert max(abs(q - balance) for q in positions) < 0.005


# --- effort jobs -----------------------------------------------------------------------------

@pytest.fixture
def weightless(shared_sim, api):
    """The robot in a paused world without gravity: link2 turns only under the efforts applied."""
    api.spawn_robot()
    api.set_gravity(0, 0, 0)
    return api


def step_effort(steps):
    """Rate gained by link2 under an effort equal to its inertia about joint1, for `steps` steps of
    1 ms: 1e-3 per step."""
    return steps * 1e-3


def aligned_future(api, lead_ns=100 * STEP_NS):
    return api.sim_time_ns() + lead_ns


def apply(api, effort, start_ns, duration_ns, joint='joint1'):
    return api.apply_joint_effort(joint, effort, ros_time(start_ns), ros_duration(duration_ns))


def test_10ms_job_acts_on_exactly_10_steps(weightless):
    api = weightless
    start = aligned_future(api)
    res = apply(api, physics.INERTIA_ABOUT_JOINT, start, 10 * STEP_NS)
    assert (res.success, res.status_message) == (True, EFFORT_SET)
    api.run_until(start + 50 * STEP_NS)
    assert api.joint()[1] == pytest.approx(step_effort(10), abs=1e-7)


def test_job_starting_in_the_past_starts_now(weightless):
    api = weightless
    assert apply(api, physics.INERTIA_ABOUT_JOINT, 0, 10 * STEP_NS).success  # start 0: now
    api.run_for(50 * STEP_NS)
    assert api.joint()[1] == pytest.approx(step_effort(10), abs=1e-7)


def test_back_to_back_jobs_give_a_constant_torque(weightless):
    api = weightless
    start = aligned_future(api)
    for k in range(5):  # a 100 Hz controller's jobs, each 10 ms
        assert apply(api, physics.INERTIA_ABOUT_JOINT, start + k * 10 * STEP_NS, 10 * STEP_NS).success
    paused_at = api.run_until(start + 25 * STEP_NS)
    steps = min((paused_at - start) // STEP_NS, 50)  # mid-way: one effort per step so far
    assert api.joint()[1] == pytest.approx(step_effort(steps), abs=1e-7)
    api.run_until(start + 100 * STEP_NS)
    # Closed windows would apply the torque twice on each of the 4 inner boundaries: 54 steps.
    assert api.joint()[1] == pytest.approx(step_effort(50), abs=1e-7)


def test_two_jobs_on_one_joint_sum(weightless):
    api = weightless
    start = aligned_future(api)
    assert apply(api, 0.25 * physics.INERTIA_ABOUT_JOINT, start, 10 * STEP_NS).success
    assert apply(api, 0.75 * physics.INERTIA_ABOUT_JOINT, start + 5 * STEP_NS, 10 * STEP_NS).success
    api.run_until(start + 50 * STEP_NS)
    assert api.joint()[1] == pytest.approx(0.25 * step_effort(10) + 0.75 * step_effort(10),
                                           abs=1e-7)


def test_endless_job_acts_until_cleared(weightless):
    api = weightless
    res = api.apply_joint_effort('joint1', physics.INERTIA_ABOUT_JOINT, ros_time(0),
                                 ros_duration(FOREVER_NS))  # duration -1 s
    assert res.success, res.status_message
    # Exactly 30 steps however busy the machine (a running world, paused by a request, may take
    # hundreds, and then the link's turning shows in the rate beyond the tolerance of a step).
    assert api.step_simulation(30).success
    api.clear_joint_forces('joint1')
    cleared_rate = api.joint()[1]
    assert cleared_rate == pytest.approx(step_effort(30), abs=1e-7)
    assert api.step_simulation(30).success
    assert api.joint()[1] == pytest.approx(cleared_rate, abs=1e-9)


def test_zero_duration_job_does_nothing_and_says_so(weightless):
    api = weightless
    res = apply(api, physics.INERTIA_ABOUT_JOINT, 0, 0)
    assert res.success and res.status_message.startswith('ApplyJointEffort: ')
    assert res.status_message != EFFORT_SET, 'status_message must say nothing was queued'
    api.run_for(30 * STEP_NS)
    assert api.joint() == (0.0, 0.0)


def test_job_shorter_than_a_step_acts_on_one_step_and_says_so(weightless):
    api = weightless
    start = aligned_future(api)
    res = apply(api, physics.INERTIA_ABOUT_JOINT, start, 400000)  # 0.4 ms
    assert res.success and res.status_message.startswith('ApplyJointEffort: ')
    assert res.status_message != EFFORT_SET, 'status_message must say it acts for one step'
    api.run_until(start + 30 * STEP_NS)
    assert api.joint()[1] == pytest.approx(step_effort(1), abs=1e-7)


# --- pause, reset, clock ---------------------------------------------------------------------

def clock_listener(ros, rospy):
    """Subscribes /clock, connected to the simulator on both sides; returns (received clock times
    in ns, subscriber). Every message is kept: under use_sim_time rospy subscribes /clock itself
    with queue_size 1, and this subscriber shares that connection, which would drop all but the
    last message of each read from the socket whenever this process runs late (a busy machine).
    /clock is latched, and rospy hands a callback added to a connection the latched time from the
    adding thread while its receiving thread may already have handed over a newer one: the first
    time heard may come out of order (what_was_sent drops it). The subscriber counts the
    connection once the simulator's reply to its header has come, before the simulator's network
    thread has added it to /clock's subscribers (a busy machine keeps that thread from it for tens
    of ms): so this waits until the simulator lists the connection too, after which every clock
    published reaches it."""
    from rosgraph_msgs.msg import Clock
    stamps = []
    sub = rospy.Subscriber('/clock', Clock, lambda m: stamps.append(m.clock.to_nsec()))
    wait_until(lambda: sub.get_num_connections() > 0, 30, what='/clock connection')
    for connection in sub.impl.connections:
        connection.protocol.queue_size = None
    wait_until(lambda: ros.connected('/gazebo', '/clock', rospy.get_name()), 30,
               what="the simulator's side of the /clock connection")
    return stamps, sub


def what_was_sent(stamps):
    """The clock times heard after the first, which may be rospy's late replay of the latched one
    (clock_listener)."""
    return stamps[1:]


def test_pause_freezes_clock_and_joint_unpause_resumes(ros, shared_sim, api, rospy_client):
    api.unpause_physics()
    api.spawn_robot()
    assert api.set_model_configuration(ROBOT, '', ['joint1'], [0.3]).success
    stamps, _ = clock_listener(ros, rospy_client)
    wait_until(lambda: len(stamps) > 10, 30, what='/clock')
    api.pause_physics()
    frozen = api.sim_time_ns(), api.joint()
    count = len(stamps)
    # A request of no steps is answered by the loop itself, once it has gone round: the paused
    # loop has had its turn since the pause, and took no step.
    assert api.step_simulation(0).sim_time.to_nsec() == frozen[0]
    assert (api.sim_time_ns(), api.joint()) == frozen
    # What arrived meanwhile was sent before the pause, late on a busy machine: times up to the
    # frozen one, each once (a paused world publishing its time again would repeat it).
    late = stamps[count - 1:]
    assert late == sorted(set(late)) and max(stamps) <= frozen[0], late
    api.unpause_physics()
    wait_until(lambda: api.sim_time_ns() > frozen[0] and api.joint()[0] != frozen[1][0], 30,
               what='time and joint to move on')
    wait_until(lambda: max(stamps) > frozen[0], 30, what='/clock to move on')
    # And nothing went out twice meanwhile: the stream heard through the pause, in its order.
    assert what_was_sent(stamps) == sorted(set(what_was_sent(stamps)))


def test_clock_starts_at_first_step_and_advances_every_step(ros, engine, rospy_client):
    # Its own simulator: what a node publishes from its start (a shared one has run before, and
    # /clock is latched: a new subscriber gets the last time published). At 100 steps a wall
    # second: the node holds a step's clock back only once roscpp's network thread is 100 clocks
    # behind (sim_loop's budget), which at this rate is a second without a turn for that thread.
    start_sim(ros, engine, ['-u', '_max_update_rate:=100'])
    api = GazeboApi(rospy_client)
    assert ros.master().getParam('/test', '/use_sim_time')[2] is True
    stamps, _ = clock_listener(ros, rospy_client)
    api.unpause_physics()
    wait_until(lambda: len(stamps) > 200, 60, what='200 /clock messages')
    # Paused, no /clock at all, in particular no clock of 0: the first one heard is the first
    # step's (a clock published before it, latched or not, would come first on the connection).
    assert stamps[0] == STEP_NS
    received = stamps[:200]
    assert [b - a for a, b in zip(received, received[1:])] == [STEP_NS] * 199, received


def test_a_free_running_world_stops_with_its_time_on_the_clock(ros, engine, rospy_client):
    """Free-running, the world steps faster than roscpp's network thread writes clocks, and a
    step's time past the thread's budget is held for a later step's clock: where the world stops,
    its own time goes out, and what a subscriber heard only ever moved forward."""
    start_sim(ros, engine, ['_max_update_rate:=0'])
    api = GazeboApi(rospy_client)
    stamps, _ = clock_listener(ros, rospy_client)
    wait_until(lambda: len(stamps) > 100, 60, what='100 /clock messages')
    api.pause_physics()
    stopped_ns = api.sim_time_ns()
    wait_until(lambda: stamps[-1] == stopped_ns, 30, what='the clock at the stopped time')
    assert what_was_sent(stamps) == sorted(set(what_was_sent(stamps)))


def test_pub_clock_frequency_throttles_clock(ros, engine, rospy_client):
    ros.set_param('/gazebo/pub_clock_frequency', 50)
    start_sim(ros, engine)
    stamps, _ = clock_listener(ros, rospy_client)
    wait_until(lambda: len(stamps) > 20, 60, what='20 /clock messages')
    gaps = {b - a for a, b in zip(stamps[:20], stamps[1:20])}
    assert gaps == {20 * STEP_NS}


def test_pub_clock_frequency_set_on_a_restarted_roscore_throttles_clock(ros, engine, rospy_client):
    """The node reads pub_clock_frequency through roscpp's cache, which the master it subscribed
    to keeps up to date: a restarted master gets that subscription again."""
    sim = start_sim(ros, engine)
    ros.restart_master()
    ros.wait_until(lambda: 'the ROS master came back' in ros.log_text(sim), 60,
                   what='the simulator to register again with the new master')
    ros.set_param('/gazebo/pub_clock_frequency', 50)
    stamps, _ = clock_listener(ros, rospy_client)
    # Updates reach the node's cache shortly after they are set: the gaps settle at 20 steps.
    wait_until(lambda: len(stamps) > 40 and
               {b - a for a, b in zip(stamps[-20:], stamps[-19:])} == {20 * STEP_NS}, 60,
               what='/clock every 20 steps')


def test_use_sim_time_already_set_is_kept(ros, engine):
    ros.set_param('/use_sim_time', False)
    start_sim(ros, engine)
    assert ros.master().getParam('/test', '/use_sim_time')[2] is False


def robot_moved_then_paused(api):
    """The robot spawned, moved off its spawn pose, 0.3 s of sim time run, then paused."""
    api.unpause_physics()
    api.spawn_robot()
    assert api.set_model_configuration(ROBOT, '', ['joint1'], [0.3]).success
    wait_until(lambda: api.sim_time_ns() > 300 * STEP_NS, 60, what='sim time 0.3 s')
    api.pause_physics()


def test_reset_simulation_returns_time_and_robot_to_spawn(shared_sim, api):
    robot_moved_then_paused(api)
    assert api.joint() != (0.0, 0.0)
    api.reset_simulation()
    assert api.get_world_properties().sim_time == 0.0
    assert api.joint() == (0.0, 0.0)
    assert ROBOT in api.get_world_properties().model_names


def test_reset_simulation_puts_its_time_on_the_latched_clock(ros, shared_sim, api,
                                                            rospy_client):
    robot_moved_then_paused(api)
    paused_at = api.sim_time_ns()
    stamps, _ = clock_listener(ros, rospy_client)
    wait_until(lambda: stamps and stamps[-1] == paused_at > 0, 30, what='/clock of the pause')
    api.reset_simulation()
    # A node's time goes back with the world's, and a node subscribing afterwards starts from
    # the reset time, not from the time the world had before it.
    wait_until(lambda: stamps[-1] == 0, 30, what='/clock of the reset')
    wait_until(lambda: rospy_client.get_rostime().to_nsec() == 0, 30, what="the client's time")
    later, _ = clock_listener(ros, rospy_client)
    wait_until(lambda: later, 30, what='the latched /clock')
    assert later == [0]


def test_reset_world_resets_poses_while_time_runs_on(shared_sim, api):
    robot_moved_then_paused(api)
    paused_at = api.sim_time_ns()
    api.reset_world()
    assert api.sim_time_ns() == paused_at
    assert api.joint() == (0.0, 0.0)
    api.unpause_physics()
    wait_until(lambda: api.sim_time_ns() > paused_at, 30, what='time to run on')


def test_reset_drops_pending_jobs(shared_sim, api):
    api.spawn_robot()
    api.set_gravity(0, 0, 0)
    endless = ros_duration(FOREVER_NS)
    assert api.apply_joint_effort('joint1', 1.0, ros_time(0), endless).success
    api.reset_world()
    api.run_for(30 * STEP_NS)
    assert api.joint() == (0.0, 0.0)


# --- models, links, properties: happy and error paths ----------------------------------------

def test_delete_model(shared_sim, api):
    api.spawn_robot()
    res = api.delete_model(ROBOT)
    assert (res.success, res.status_message) == (True, 'DeleteModel: successfully deleted model')
    assert ROBOT not in api.get_world_properties().model_names
    assert not api.get_joint_properties('joint1').success
    res = api.delete_model(ROBOT)
    assert (res.success, res.status_message) == (False, 'DeleteModel: model does not exist')


def test_spawn_model_relative_to_a_reference_frame_and_both_formats(shared_sim, api):
    api.spawn_robot()
    # The box placed 0.5 m above link2's frame (at z 1.0): z = 1.5.
    res = api.spawn_sdf_model('box', BOX_SDF, '/ns', pose(z=0.5), ROBOT + '::link2')
    assert (res.success, res.status_message) == (True, 'SpawnModel: Successfully spawned entity')
    state = api.get_model_state('box', '')
    assert state.success and state.pose.position.z == pytest.approx(1.5, abs=1e-9)
    # Gazebo takes a URDF on spawn_sdf_model too (it converts URDF to SDF).
    res = api.spawn_sdf_model('robot2', tutorial_urdf(), '', pose(x=2.0), '')
    assert res.success, res.status_message
    assert api.get_model_state('robot2', 'world').pose.position.x == pytest.approx(2.0)


def test_spawn_urdf_with_gazebo_tags(shared_sim, api):
    urdf = tutorial_urdf().replace(
        '</robot>', '<gazebo reference="link2"><material>Gazebo/Red</material></gazebo>\n'
                    '<gazebo><plugin name="x" filename="libx.so"/></gazebo>\n</robot>')
    res = api.spawn_urdf_model(ROBOT, urdf, '', pose(), '')
    assert res.success, res.status_message
    assert api.joint() == (0.0, 0.0)


def test_get_and_set_model_state(shared_sim, api):
    api.spawn_box()
    target = pose(1.0, 2.0, 3.0)
    target.orientation.w, target.orientation.z = math.cos(0.25), math.sin(0.25)
    from gazebo_msgs.msg import ModelState
    res = api.set_model_state(ModelState('box', target, None, 'world'))
    assert res.success, res.status_message
    state = api.get_model_state('box', 'world')
    assert (state.success, state.status_message) == (True, 'GetModelState: got properties')
    assert state.header.frame_id == 'world'
    got = state.pose
    assert (got.position.x, got.position.y, got.position.z) == pytest.approx((1, 2, 3))
    assert (got.orientation.w, got.orientation.z) == pytest.approx(
        (math.cos(0.25), math.sin(0.25)))
    res = api.get_model_state('nobody', '')
    assert (res.success, res.status_message) == (False, 'GetModelState: model does not exist')
    assert not api.set_model_state(ModelState('nobody', target, None, '')).success


def test_all_zero_quaternion_is_the_identity_as_in_gazebo(shared_sim, api):
    # An unset orientation (all zero) normalises to the identity, as Gazebo's does: the book's
    # `rosservice call /gazebo/set_model_state '{model_state: {model_name: NAME, pose:
    # {position: {z: 4.0}}}}'` sends one.
    from gazebo_msgs.msg import ModelState
    from geometry_msgs.msg import Pose
    unset = Pose()
    unset.position.z = 2.0
    res = api.spawn_sdf_model('box', BOX_SDF, '', unset, '')
    assert (res.success, res.status_message) == (True, 'SpawnModel: Successfully spawned entity')
    spawned = api.get_model_state('box', '').pose
    assert (spawned.position.z, spawned.orientation.w, spawned.orientation.x,
            spawned.orientation.y, spawned.orientation.z) == (2.0, 1.0, 0.0, 0.0, 0.0)
    turned = pose(z=1.0)
    turned.orientation.w, turned.orientation.z = math.cos(0.25), math.sin(0.25)
    assert api.set_model_state(ModelState('box', turned, None, '')).success
    unset.position.z = 4.0
    res = api.set_model_state(ModelState('box', unset, None, ''))
    assert (res.success, res.status_message) == (True, 'SetModelState: set model state done')
    moved = api.get_model_state('box', '').pose
    assert (moved.position.z, moved.orientation.w, moved.orientation.x, moved.orientation.y,
            moved.orientation.z) == (4.0, 1.0, 0.0, 0.0, 0.0)


def test_set_model_state_topic(shared_sim, api, rospy_client):
    api.spawn_box()
    from gazebo_msgs.msg import ModelState
    pub = rospy_client.Publisher('/gazebo/set_model_state', ModelState, queue_size=1)
    wait_until(lambda: pub.get_num_connections() > 0, 30, what='set_model_state subscription')
    pub.publish(ModelState('box', pose(0.5, 0, 2.0), None, ''))
    wait_until(lambda: api.get_model_state('box', '').pose.position.z == pytest.approx(2.0), 30,
               what='the box to move')


def test_get_and_set_link_state(shared_sim, api):
    api.spawn_robot()
    api.spawn_box()
    res = api.get_link_state(ROBOT + '::link2', '')
    assert res.success, res.status_message
    assert res.link_state.link_name == ROBOT + '::link2'
    assert res.link_state.pose.position.z == pytest.approx(1.0, abs=1e-9)  # the joint origin
    from gazebo_msgs.msg import LinkState
    res = api.set_link_state(LinkState('box::body', pose(0, 1.0, 0.5), None, ''))
    assert res.success, res.status_message
    got = api.get_link_state('box::body', 'world').link_state.pose.position
    assert (got.x, got.y, got.z) == pytest.approx((0, 1.0, 0.5))
    res = api.get_link_state('link9', '')
    assert (res.success, res.status_message) == (
        False, 'GetLinkState: link not found, did you forget to scope the link by model name?')
    assert not api.set_link_state(LinkState('nobody::body', pose(), None, '')).success


def test_model_world_and_link_properties(shared_sim, api):
    api.spawn_robot()
    res = api.get_model_properties(ROBOT)
    assert (res.success, res.status_message) == (True, 'GetModelProperties: got properties')
    assert {'link1', 'link2'} <= set(res.body_names)
    assert 'joint1' in res.joint_names and not res.is_static
    res = api.get_model_properties('nobody')
    assert (res.success, res.status_message) == (False, 'GetModelProperties: model does not exist')

    res = api.get_world_properties()
    assert (res.success, res.status_message) == (True, 'GetWorldProperties: got properties')
    assert ROBOT in res.model_names and res.sim_time == 0.0

    res = api.get_link_properties(ROBOT + '::link2')
    assert (res.success, res.status_message) == (True, 'GetLinkProperties: got properties')
    assert (res.mass, res.ixx, res.iyy, res.izz) == pytest.approx((1.0, 0.1, 0.1, 0.005))
    assert (res.ixy, res.ixz, res.iyz) == (0.0, 0.0, 0.0)
    assert res.com.position.z == pytest.approx(0.5) and res.gravity_mode
    assert not api.get_link_properties(ROBOT + '::link9').success


def test_physics_properties(shared_sim, engine, api):
    res = api.get_physics_properties()
    # The message has no engine field; the status names the engine that runs.
    assert (res.success, res.status_message) == (
        True, 'GetPhysicsProperties: got properties (engine: %s)' % engine)
    assert (res.time_step, res.pause, res.max_update_rate) == (0.001, True, 1000.0)
    assert (res.gravity.x, res.gravity.y, res.gravity.z) == (0.0, 0.0, -9.8)
    res.gravity.z = -1.62
    res.ode_config.sor_pgs_iters = 80
    set_res = api.set_physics_properties(0.002, 500.0, res.gravity, res.ode_config)
    assert set_res.success, set_res.status_message
    got = api.get_physics_properties()
    assert (got.time_step, got.max_update_rate, got.gravity.z) == (0.002, 500.0, -1.62)
    assert got.ode_config.sor_pgs_iters == 80
    bad = api.set_physics_properties(0.0, 500.0, res.gravity, res.ode_config)
    assert not bad.success and bad.status_message
    assert api.get_physics_properties().time_step == 0.002


def test_start_up_parameters(ros, engine, api):
    start_sim(ros, engine, ['-u', '_time_step:=0.002', '_max_update_rate:=0',
                            '_gravity:=[0.0, 0.0, -1.0]'])
    res = api.get_physics_properties()
    assert (res.time_step, res.pause, res.max_update_rate, res.gravity.z) == (
        0.002, True, 0.0, -1.0)


def test_invalid_start_up_parameter_stops_the_node_with_a_message(ros, engine):
    proc = start_sim(ros, engine, ['_time_step:=-1'], wait=False)
    assert proc.wait(timeout=300) != 0
    assert 'time_step' in ros.log_text(proc) or 'step' in ros.log_text(proc)


def test_set_model_configuration(shared_sim, api):
    api.spawn_robot()
    res = api.set_model_configuration(ROBOT, 'robot_description', ['joint1'], [1.0])
    assert (res.success, res.status_message) == (True, 'SetModelConfiguration: success')
    assert api.joint() == (pytest.approx(1.0), 0.0)
    assert not api.set_model_configuration('nobody', '', ['joint1'], [1.0]).success
    assert not api.set_model_configuration(ROBOT, '', ['joint1'], [1.0, 2.0]).success
    assert api.joint() == (pytest.approx(1.0), 0.0)


def test_apply_and_clear_body_wrench(shared_sim, api):
    api.spawn_box(initial_pose=pose(z=1.0))  # clear of the ground
    api.set_gravity(0, 0, 0)
    from geometry_msgs.msg import Point, Wrench
    wrench = Wrench()
    wrench.force.x = 1.0
    started = api.sim_time_ns()
    res = api.apply_body_wrench('box::body', '', Point(), wrench, ros_time(0),
                                ros_duration(FOREVER_NS))
    assert res.success, res.status_message
    cleared = api.run_for(100 * STEP_NS)
    api.clear_body_wrenches('box::body')
    moving = api.get_model_state('box', '').twist.linear.x
    assert moving == pytest.approx((cleared - started) * 1e-9, abs=1e-7)  # F t / m, 1 N on 1 kg
    api.run_for(50 * STEP_NS)
    assert api.get_model_state('box', '').twist.linear.x == pytest.approx(moving, abs=1e-9)
    assert not api.apply_body_wrench('nobody::body', '', Point(), wrench, ros_time(0),
                                     ros_duration(10 ** 9)).success


def test_model_and_link_states_topics(shared_sim, api, rospy_client):
    api.unpause_physics()
    api.spawn_robot()
    from gazebo_msgs.msg import LinkStates, ModelStates
    models = rospy_client.wait_for_message('/gazebo/model_states', ModelStates, timeout=30)
    assert ROBOT in models.name
    links = rospy_client.wait_for_message('/gazebo/link_states', LinkStates, timeout=30)
    assert ROBOT + '::link2' in links.name
    assert len(links.pose) == len(links.twist) == len(links.name)


def test_collision_markers(shared_sim, api, rospy_client):
    api.spawn_robot()
    api.unpause_physics()
    from visualization_msgs.msg import Marker, MarkerArray
    msg = rospy_client.wait_for_message('/gazebo/collision_markers', MarkerArray, timeout=30)
    shapes = [m for m in msg.markers if m.action == Marker.ADD]
    assert all(m.header.frame_id == 'world' for m in shapes)
    cylinders = [m for m in shapes if m.type == Marker.CYLINDER]
    assert len(cylinders) == 1
    assert (cylinders[0].scale.x, cylinders[0].scale.z) == pytest.approx((0.2, 1.0))


# --- bad input: success False with a message; the node and its world carry on ----------------

def nan_pose():
    p = pose()
    p.position.x = float('nan')
    return p


def bad_requests(api):
    """(what, call) for every kind of bad input; each call returns a response with success."""
    from geometry_msgs.msg import Point, Twist, Vector3, Wrench
    from gazebo_msgs.msg import LinkState, ModelState
    nan_twist = Twist()
    nan_twist.angular.y = float('inf')
    nan_wrench = Wrench()
    nan_wrench.force.z = float('nan')
    physics = api.get_physics_properties()
    nan_gravity = Vector3(0, float('nan'), 0)
    ok_gravity = physics.gravity
    forever = ros_duration(FOREVER_NS)
    return [
        ('unknown joint', lambda: api.get_joint_properties('joint9')),
        ('effort on unknown joint', lambda: api.apply_joint_effort('joint9', 1, ros_time(0),
                                                                   forever)),
        ('NaN effort', lambda: api.apply_joint_effort('joint1', float('nan'), ros_time(0),
                                                      forever)),
        ('infinite effort', lambda: api.apply_joint_effort('joint1', float('inf'), ros_time(0),
                                                           forever)),
        ('bad XML', lambda: api.spawn_urdf_model('m', '<robot name="m"><link', '', pose(), '')),
        ('not a model', lambda: api.spawn_urdf_model('m', '<foo/>', '', pose(), '')),
        ('empty XML', lambda: api.spawn_sdf_model('m', '', '', pose(), '')),
        ('duplicate name', lambda: api.spawn_urdf_model(ROBOT, tutorial_urdf(), '', pose(), '')),
        ('unknown reference frame', lambda: api.spawn_sdf_model('m', BOX_SDF, '', pose(),
                                                                'nobody::body')),
        ('NaN spawn pose', lambda: api.spawn_sdf_model('m', BOX_SDF, '', nan_pose(), '')),
        ('delete unknown model', lambda: api.delete_model('nobody')),
        ('state of unknown model', lambda: api.get_model_state('nobody', '')),
        ('state relative to unknown entity', lambda: api.get_model_state(ROBOT, 'nobody::x')),
        ('set unknown model', lambda: api.set_model_state(ModelState('nobody', pose(), None, ''))),
        ('NaN model pose', lambda: api.set_model_state(ModelState(ROBOT, nan_pose(), None, ''))),
        ('infinite model twist', lambda: api.set_model_state(ModelState(ROBOT, pose(), nan_twist,
                                                                         ''))),
        ('unknown link state', lambda: api.get_link_state('nobody::link', '')),
        ('set unknown link', lambda: api.set_link_state(LinkState('nobody::x', pose(), None, ''))),
        ('NaN link pose', lambda: api.set_link_state(LinkState(ROBOT + '::link2', nan_pose(),
                                                               None, ''))),
        ('unknown link properties', lambda: api.get_link_properties('nobody::link')),
        ('unknown model properties', lambda: api.get_model_properties('nobody')),
        ('configuration of unknown model', lambda: api.set_model_configuration(
            'nobody', '', ['joint1'], [1.0])),
        ('configuration of unknown joint', lambda: api.set_model_configuration(
            ROBOT, '', ['joint9'], [1.0])),
        ('configuration length mismatch', lambda: api.set_model_configuration(
            ROBOT, '', ['joint1'], [])),
        ('NaN configuration', lambda: api.set_model_configuration(
            ROBOT, '', ['joint1'], [float('nan')])),
        ('zero step', lambda: api.set_physics_properties(0.0, 1000.0, ok_gravity,
                                                         physics.ode_config)),
        ('negative step', lambda: api.set_physics_properties(-0.001, 1000.0, ok_gravity,
                                                             physics.ode_config)),
        ('NaN step', lambda: api.set_physics_properties(float('nan'), 1000.0, ok_gravity,
                                                        physics.ode_config)),
        ('NaN gravity', lambda: api.set_physics_properties(0.001, 1000.0, nan_gravity,
                                                           physics.ode_config)),
        ('negative max_update_rate', lambda: api.set_physics_properties(
            0.001, -1.0, ok_gravity, physics.ode_config)),
        ('wrench on unknown body', lambda: api.apply_body_wrench(
            'nobody::x', '', Point(), Wrench(), ros_time(0), forever)),
        ('NaN wrench', lambda: api.apply_body_wrench(
            ROBOT + '::link2', '', Point(), nan_wrench, ros_time(0), forever)),
        ('wrench in unknown frame', lambda: api.apply_body_wrench(
            ROBOT + '::link2', 'nobody::x', Point(), Wrench(), ros_time(0), forever)),
    ]


def world_snapshot(api):
    physics = api.get_physics_properties()
    return (api.get_world_properties().model_names, api.joint(),
            api.get_model_state(ROBOT, '').pose, physics.time_step, physics.max_update_rate,
            physics.gravity)


def test_bad_input_is_refused_and_the_world_is_unchanged(shared_sim, api):
    api.spawn_robot()
    assert api.set_model_configuration(ROBOT, '', ['joint1'], [0.7]).success
    before = world_snapshot(api)
    problems = []
    for what, call in bad_requests(api):
        res = call()
        if res.success or not res.status_message:
            problems.append('%s: success %s, status %r' % (what, res.success, res.status_message))
        if world_snapshot(api) != before:
            problems.append('%s changed the world' % what)
    assert not problems, '\n'.join(problems)
    # Still serving, with its world intact: unpaused, the link moves on from where it was.
    api.unpause_physics()
    wait_until(lambda: api.joint()[0] != 0.7, 30, what='the joint to move after unpause')


# --- a client built against gazebo_msgs --------------------------------------------------------

def test_python_client_of_gazebo_msgs_drives_the_node(shared_sim, rospy_client):
    from gazebo_msgs.srv import GetJointProperties, SpawnModel
    spawn = rospy_client.ServiceProxy('/gazebo/spawn_urdf_model', SpawnModel)
    res = spawn(ROBOT, tutorial_urdf(), '', pose(), '')
    assert (res.success, res.status_message) == (True, 'SpawnModel: Successfully spawned entity')
    props = rospy_client.ServiceProxy('/gazebo/get_joint_properties', GetJointProperties)('joint1')
    assert (props.type, props.position, props.success) == (GetJointProperties._response_class.REVOLUTE,
                                                           (0.0,), True)


# --- Gazebo's status texts where Gazebo refuses the same input -------------------------------

def test_status_texts_are_gazebos(shared_sim, api):
    api.spawn_robot()
    from gazebo_msgs.msg import LinkState, ModelState
    from geometry_msgs.msg import Point, Wrench
    forever = ros_duration(FOREVER_NS)
    expected = [
        (api.spawn_urdf_model(ROBOT, tutorial_urdf(), '', pose(), ''),
         'SpawnModel: Failure - entity already exists.'),
        (api.spawn_sdf_model('m', BOX_SDF, '', pose(), 'nobody::body'),
         'SpawnModel: reference reference_frame not found, did you forget to scope the link by '
         'model name?'),
        (api.spawn_urdf_model('m', '<foo/>', '', pose(), ''),
         'GazeboRosApiPlugin SpawnModel Failure: input model_xml not SDF or URDF, or cannot be '
         'converted to Gazebo compatible format.'),
        (api.get_model_state(ROBOT, 'nobody::x'),
         'GetModelState: reference relative_entity_name not found, did you forget to scope the '
         'body by model name?'),
        (api.set_model_state(ModelState('nobody', pose(), None, '')),
         'SetModelState: model does not exist'),
        (api.set_model_state(ModelState(ROBOT, pose(), None, 'nobody::x')),
         'SetModelState: specified reference frame entity does not exist'),
        (api.get_link_state(ROBOT + '::link2', 'nobody::x'),
         'GetLinkState: reference reference_frame not found, did you forget to scope the link by '
         'model name?'),
        (api.set_link_state(LinkState('nobody::x', pose(), None, '')),
         'SetLinkState: link does not exist'),
        (api.set_link_state(LinkState(ROBOT + '::link2', pose(), None, 'nobody::x')),
         'SetLinkState: failed'),
        (api.apply_body_wrench('nobody::x', '', Point(), Wrench(), ros_time(0), forever),
         'ApplyBodyWrench: body does not exist'),
        (api.apply_body_wrench(ROBOT + '::link2', 'nobody::x', Point(), Wrench(), ros_time(0),
                               forever),
         'ApplyBodyWrench: reference_frame not found'),
        (api.set_model_configuration('nobody', '', ['joint1'], [1.0]),
         'SetModelConfiguration: model does not exist'),
        (api.set_model_configuration(ROBOT, '', ['joint1'], []),
         'SetModelConfiguration: joint name and position list have different lengths'),
        (api.get_link_properties('nobody::x'),
         'GetLinkProperties: link not found, did you forget to scope the link by model name?'),
    ]
    wrong = ['%r != %r' % (res.status_message, text) for res, text in expected
             if (res.success, res.status_message) != (False, text)]
    assert not wrong, '\n'.join(wrong)
    physics = api.get_physics_properties()
    res = api.set_physics_properties(physics.time_step, physics.max_update_rate, physics.gravity,
                                     physics.ode_config)
    assert (res.success, res.status_message) == (True, 'physics engine updated')


# --- set_joint_properties, set_link_properties, lights ----------------------------------------

def joint_config(**fields):
    from gazebo_msgs.msg import ODEJointProperties
    return ODEJointProperties(**fields)


def test_set_joint_properties_damping_acts(shared_sim, api):
    api.spawn_robot()
    api.set_gravity(0, 0, 0)
    res = api.set_joint_properties('joint1', joint_config(damping=[physics.INERTIA_ABOUT_JOINT]))
    assert (res.success, res.status_message) == (True, 'SetJointProperties: properties set')
    assert api.get_joint_properties('joint1').damping == (physics.INERTIA_ABOUT_JOINT,)
    # A kick of 1 rad/s decays as exp(-t) under damping I. The world pauses some steps after the
    # time asked for (later on a busy machine), so the decay is taken at the times it paused at.
    start = aligned_future(api)
    assert apply(api, physics.INERTIA_ABOUT_JOINT * 1000.0, start, STEP_NS).success
    first_ns = api.run_until(start + STEP_NS)
    first = api.joint()[1]
    assert first == pytest.approx(math.exp(-(first_ns - start - STEP_NS) * 1e-9), rel=0.01)
    second_ns = api.run_for(500 * STEP_NS)
    assert api.joint()[1] == pytest.approx(first * math.exp(-(second_ns - first_ns) * 1e-9),
                                           rel=0.02)


def test_top_damping_holds_the_link_where_its_effort_balances_gravity(shared_sim, api):
    # Damping at the top of the accepted range (1e6) on the upright side, where gravity alone
    # would tip the link over: the effort -m g d sin(0.51) balances gravity at 0.51 rad. Kicked
    # there by 50 N m for one step (0.05 N m s: a damper gives way by 0.05 / 1e6 rad), the link
    # stays, neither swinging apart (as an explicit -b qdot would, 1400 times past its limit) nor
    # creeping off.
    api.spawn_robot()
    balance = 0.51
    effort = -physics.MASS * physics.GRAVITY * physics.COM_DISTANCE * math.sin(balance)
    assert api.set_model_configuration(ROBOT, '', ['joint1'], [balance]).success
    res = api.set_joint_properties('joint1', joint_config(damping=[1e6]))
    assert (res.success, res.status_message) == (True, 'SetJointProperties: properties set')
    assert apply(api, effort, 0, FOREVER_NS).success
    assert apply(api, 50.0, 0, STEP_NS).success
    api.run_for(2 * 10 ** 9)
    position, rate = api.joint()
    assert position == pytest.approx(balance, abs=1e-6)
    assert abs(rate) < 1e-6


def test_set_joint_properties_refuses_what_it_cannot_set(shared_sim, api):
    api.spawn_robot()
    res = api.set_joint_properties('joint9', joint_config(damping=[1.0]))
    assert (res.success, res.status_message) == (False, 'SetJointProperties: joint not found')
    res = api.set_joint_properties('joint1', joint_config(damping=[1.0], hiStop=[1.0]))
    assert not res.success and 'hiStop' in res.status_message
    res = api.set_joint_properties('joint1', joint_config(damping=[-1.0]))
    assert not res.success and 'damping' in res.status_message
    assert api.get_joint_properties('joint1').damping == ()  # the URDF declares none


def link_properties_request(props, **changes):
    fields = dict(com=props.com, gravity_mode=props.gravity_mode, mass=props.mass,
                  ixx=props.ixx, ixy=props.ixy, ixz=props.ixz, iyy=props.iyy, iyz=props.iyz,
                  izz=props.izz)
    fields.update(changes)
    return fields


def swing_period(api, amplitude):
    res = api.set_model_configuration(ROBOT, '', ['joint1'], [math.pi + amplitude])
    assert res.success, res.status_message
    samples = paused_samples(api, api.sim_time_ns() + int(4.5 * 1e9))
    crossings = zero_crossings(samples, math.pi)
    assert len(crossings) >= 4, crossings
    return 2 * (crossings[-1] - crossings[0]) / (len(crossings) - 1)


def test_set_link_properties_changes_the_swing_and_refuses_what_no_body_has(shared_sim, api):
    api.spawn_robot(initial_pose=pose(z=1.0))
    link = ROBOT + '::link2'
    props = api.get_link_properties(link)
    res = api.set_link_properties(link_name=link, **link_properties_request(props))
    assert (res.success, res.status_message) == (True, 'SetLinkProperties: properties set')
    heavy = 2 * physics.MASS
    res = api.set_link_properties(link_name=link, **link_properties_request(props, mass=heavy))
    assert (res.success, res.status_message) == (True, 'SetLinkProperties: properties set')
    assert api.get_link_properties(link).mass == heavy
    amplitude = 0.05
    assert swing_period(api, amplitude) == pytest.approx(pendulum_period(amplitude, heavy),
                                                         rel=0.005)
    assert pendulum_period(amplitude, heavy) < 0.95 * pendulum_period(amplitude)

    for change, text in [
            (dict(mass=-1.0), 'mass must be >= 0, and > 0 for a link that moves (welded links: in sum)'),
            (dict(mass=0.0), 'mass must be >= 0, and > 0 for a link that moves (welded links: in sum)'),
            (dict(ixy=10.0), "the inertia must be positive definite, as a rigid body's is (ixx, "
                             "iyy, izz > 0 and the products small enough)"),
            (dict(izz=float('nan')), 'mass, com and the inertia must be finite')]:
        res = api.set_link_properties(link_name=link, **link_properties_request(props, **change))
        assert (res.success, res.status_message) == (False, 'SetLinkProperties: ' + text), change
    assert api.get_link_properties(link).mass == heavy
    res = api.set_link_properties(link_name=ROBOT + '::link9', **link_properties_request(props))
    assert (res.success, res.status_message) == (
        False, 'SetLinkProperties: link not found, did you forget to scope the link by model name?')


def test_set_link_properties_gravity_mode_off_floats(shared_sim, api):
    api.spawn_robot(initial_pose=pose(z=1.0))
    link = ROBOT + '::link2'
    props = api.get_link_properties(link)
    res = api.set_model_configuration(ROBOT, '', ['joint1'], [math.pi / 2])  # horizontal
    assert res.success, res.status_message
    res = api.set_link_properties(link_name=link,
                                  **link_properties_request(props, gravity_mode=False))
    assert res.success, res.status_message
    assert api.get_link_properties(link).gravity_mode is False
    api.run_for(500 * STEP_NS)
    assert api.joint()[0] == pytest.approx(math.pi / 2, abs=1e-6)
    res = api.set_link_properties(link_name=link, **link_properties_request(props))
    assert res.success, res.status_message
    api.run_for(200 * STEP_NS)
    assert api.joint()[0] > math.pi / 2 + 0.05  # gravity is back: it falls towards pi


# --- dynamic_reconfigure (/gazebo/set_parameters) ----------------------------------------------

def dynparam(ros, *args):
    """`rosrun dynamic_reconfigure dynparam ARGS`. dynparam starts with `#!/usr/bin/env python3`:
    the system Python (the one with rospy) goes first on PATH."""
    env = dict(ros.env, PATH='/usr/bin:' + ros.env['PATH'])
    out = subprocess.run(['rosrun', 'dynamic_reconfigure', 'dynparam'] + list(args), env=env,
                         capture_output=True, text=True, timeout=COMMAND_TIMEOUT)
    assert out.returncode == 0, out.stdout + out.stderr
    return out.stdout


def dynparam_get(ros):
    import ast
    return ast.literal_eval(dynparam(ros, 'get', '/gazebo'))


def test_dynparam_get_and_set_reach_the_physics(ros, shared_sim, api, rospy_client):
    # What `rosservice type` and `rostopic type` print, asked in this process.
    import rosservice
    import rostopic
    from dynamic_reconfigure.msg import Config
    assert rosservice.get_service_type('/gazebo/set_parameters') == 'dynamic_reconfigure/Reconfigure'
    for name, type_name in (('parameter_descriptions', 'ConfigDescription'),
                            ('parameter_updates', 'Config')):
        assert rostopic.get_topic_type('/gazebo/' + name)[0] == 'dynamic_reconfigure/' + type_name
    config = dynparam_get(ros)
    assert {name: config[name] for name in [
        'time_step', 'max_update_rate', 'gravity_x', 'gravity_y', 'gravity_z', 'auto_disable_bodies',
        'sor_pgs_precon_iters', 'sor_pgs_iters', 'sor_pgs_w', 'sor_pgs_rms_error_tol',
        'contact_surface_layer', 'contact_max_correcting_vel', 'cfm', 'erp', 'max_contacts']} == {
        'time_step': 0.001, 'max_update_rate': 1000.0, 'gravity_x': 0.0, 'gravity_y': 0.0,
        'gravity_z': -9.8, 'auto_disable_bodies': False, 'sor_pgs_precon_iters': 0,
        'sor_pgs_iters': 50, 'sor_pgs_w': 1.3, 'sor_pgs_rms_error_tol': 0.0,
        'contact_surface_layer': 0.001, 'contact_max_correcting_vel': 100.0, 'cfm': 0.0,
        'erp': 0.2, 'max_contacts': 20}

    dynparam(ros, 'set', '/gazebo', 'time_step', '0.002')
    dynparam(ros, 'set', '/gazebo', '{gravity_z: -1.62, sor_pgs_iters: 80}')  # several at once
    got = api.get_physics_properties()
    assert (got.time_step, got.gravity.z, got.ode_config.sor_pgs_iters) == (0.002, -1.62, 80)
    assert got.ode_config.erp == 0.2  # untouched
    # The steps are 2 ms now.
    assert api.sim_time_ns() == 0  # paused since the start
    assert api.run_for(10 * STEP_NS) % (2 * STEP_NS) == 0

    # Out of range: clamped to the advertised range, as dynamic_reconfigure servers do; a value
    # the world refuses (a zero step) leaves everything as it was.
    dynparam(ros, 'set', '/gazebo', 'erp', '5')
    assert api.get_physics_properties().ode_config.erp == 1.0
    dynparam(ros, 'set', '/gazebo', 'time_step', '0')
    assert api.get_physics_properties().time_step == 0.002

    # set_physics_properties and dynparam see one configuration.
    updates = []
    rospy_client.Subscriber('/gazebo/parameter_updates', Config, updates.append)
    got = api.get_physics_properties()
    got.gravity.z = -3.0
    res = api.set_physics_properties(got.time_step, got.max_update_rate, got.gravity,
                                     got.ode_config)
    assert res.success, res.status_message
    wait_until(lambda: updates and {p.name: p.value for p in updates[-1].doubles}['gravity_z']
               == -3.0, 60, what='parameter_updates')
    config = dynparam_get(ros)
    assert (config['gravity_z'], config['time_step']) == (-3.0, 0.002)


def test_lights_do_not_exist_as_gazebo_says(shared_sim, api):
    res = api.get_light_properties('sun')
    assert (res.success, res.status_message) == (
        False, 'getLightProperties: Requested light sun not found!')
    res = api.set_light_properties(light_name='sun')
    assert (res.success, res.status_message) == (
        False, 'setLightProperties: Requested light sun not found!')
    res = api.delete_light('sun')
    assert (res.success, res.status_message) == (False, 'DeleteLight: Requested light sun not found!')
