"""Step control (/gazebo/step_simulation) and lock-step (~lockstep) on every engine, over real ROS.

The book-shaped C++ client under lock-step is in test_book_cpp_client.py, the rospy controller in
test_controller.py, the tutorial's figures in test_tutorial.py.
"""
import re
import threading

import pytest

from api_client import GazeboApi
from conftest import start_sim
from onedof_harness.private_ros import wait_until

STEP_NS = 1000000  # the default 1 ms step
MAX_STEPS = 10000000  # the most one step request takes (the package README's limits)


@pytest.fixture
def api(ros, engine, rospy_client):
    return GazeboApi(rospy_client)


def test_step_simulation_advances_exactly_n_steps_paused_or_not(shared_sim):
    api = shared_sim  # paused at time 0, as a simulator started with -u
    reply = api.step_simulation(7)
    assert reply.success, reply.status_message
    assert (reply.sim_time.to_nsec(), reply.iterations) == (7 * STEP_NS, 7)
    assert api.sim_time_ns() == 7 * STEP_NS
    reply = api.step_simulation(0)
    assert (reply.sim_time.to_nsec(), reply.iterations) == (7 * STEP_NS, 7)

    # Running: the world pauses where it is, then steps exactly N more, and stays paused.
    api.unpause_physics()
    wait_until(lambda: api.sim_time_ns() > 50 * STEP_NS, 30, what='the world to run')
    reply = api.step_simulation(25)
    assert reply.success, reply.status_message
    assert reply.sim_time.to_nsec() == reply.iterations * STEP_NS
    paused_at = reply.iterations - 25
    assert paused_at > 50
    assert api.sim_time_ns() == reply.sim_time.to_nsec()
    assert api.step_simulation(1000).iterations == paused_at + 25 + 1000
    assert api.get_world_properties().sim_time == pytest.approx((paused_at + 1025) * 1e-3, abs=1e-9)


def test_step_simulation_from_the_command_line(ros, shared_sim):
    api = shared_sim
    result = ros.run(['rosservice', 'call', '/gazebo/step_simulation', 'steps: 250'])
    assert result.returncode == 0, result.stdout + result.stderr
    assert 'success: True' in result.stdout
    assert re.search(r'secs: 0\s+nsecs: +250000000', result.stdout), result.stdout
    assert 'iterations: 250' in result.stdout
    assert api.sim_time_ns() == 250 * STEP_NS


def test_a_step_request_over_the_limit_is_refused_naming_it(shared_sim):
    api = shared_sim
    # 2^63 and 2^64 - 1 (what -1 becomes) would run the world away for ever.
    for steps in (2 ** 63, 2 ** 64 - 1, MAX_STEPS + 1):
        reply = api.step_simulation(steps)
        assert not reply.success
        assert 'steps is %d, more than the %d one request takes' % (steps, MAX_STEPS) \
            in reply.status_message
        assert reply.iterations == 0
    assert api.sim_time_ns() == 0  # nothing stepped, still paused
    reply = api.step_simulation(5)
    assert reply.success and reply.iterations == 5


@pytest.mark.parametrize('ender', ['pause_physics', 'reset_simulation', 'unpause_physics'])
def test_pause_unpause_and_reset_end_a_step_request_and_its_caller_is_told(
        shared_sim, rospy_client, ender):
    api = shared_sim
    stepper = GazeboApi(rospy_client)  # a client of its own, as another terminal's
    replies = []
    stepping = threading.Thread(target=lambda: replies.append(stepper.step_simulation(MAX_STEPS)))
    stepping.start()
    wait_until(lambda: api.sim_time_ns() > 100 * STEP_NS, 30, what='the requested steps to run')
    getattr(api, ender)()
    stepping.join(timeout=120)
    assert replies, 'step_simulation did not answer'
    reply = replies[0]
    assert not reply.success
    taken = re.search(r'StepSimulation: %s ended the request after (\d+) of %d steps, at sim '
                      r'time [0-9.]+ s' % (ender, MAX_STEPS), reply.status_message)
    assert taken, reply.status_message
    assert 100 <= int(taken.group(1)) < MAX_STEPS
    if ender == 'unpause_physics':
        at = api.sim_time_ns()
        wait_until(lambda: api.sim_time_ns() > at, 30, what='the unpaused world to run on')
        api.pause_physics()
    # Paused, with no request left: the next one steps exactly what it asks.
    at = api.step_simulation(0).iterations
    assert api.step_simulation(3).iterations == at + 3


def test_lockstep_world_without_controllers_advances(ros, engine, api):
    start_sim(ros, engine, ['_lockstep:=true'])
    api.spawn_robot()
    wait_until(lambda: api.sim_time_ns() > 500 * STEP_NS, 30, what='the world to run')


def test_lockstep_waits_where_the_effort_runs_out_then_says_whom_it_waited_for(
        ros, engine, api, rospy_client):
    sim = start_sim(ros, engine, ['_paused:=true', '_lockstep:=true', '_lockstep_timeout:=1'])
    api.spawn_robot()
    api.step_simulation(10)
    # One 20 ms job from this node: the world runs to its end and waits there for the next one.
    res = api.apply_joint_effort('joint1', 0.5, rospy_client.Time(0),
                                 rospy_client.Duration.from_sec(0.02))
    assert res.success, res.status_message
    api.unpause_physics()
    caller = rospy_client.get_name()
    wait_until(lambda: 'the world waited 1 s (wall) at sim time 0.030 s for apply_joint_effort on '
               'joint1 (last commanded by %s)' % caller in ros.log_text(sim), 30,
               what='the lock-step timeout warning')
    log = ros.log_text(sim)
    assert 'lock-step: joint1 is commanded by %s' % caller in log
    # Then it goes on without the silent controller, and says so once.
    wait_until(lambda: api.sim_time_ns() > 100 * STEP_NS, 30, what='the world to go on')
    assert ros.log_text(sim).count('the world waited') == 1


def test_lockstep_step_simulation_answers_once_the_controller_acted(ros, engine, api,
                                                                     rospy_client):
    """The step reply comes only when the lock-stepped joint has its command for the time
    reached: here this test is the controller, and it commands in the reply's absence from
    another thread."""
    import threading
    start_sim(ros, engine, ['_paused:=true', '_lockstep:=true', '_lockstep_timeout:=30'])
    api.spawn_robot()
    api.step_simulation(10)
    period = rospy_client.Duration.from_sec(0.01)
    assert api.apply_joint_effort('joint1', 0.1, rospy_client.Time(0), period).success
    replies = []
    stepping = threading.Thread(target=lambda: replies.append(api.step_simulation(15)))
    stepping.start()
    # The world stops at 0.020 s, where the job ends, until the next command.
    wait_until(lambda: api.sim_time_ns() == 20 * STEP_NS, 30, what='the world at 0.020 s')
    assert not replies
    commander = GazeboApi(rospy_client)
    assert commander.apply_joint_effort('joint1', 0.1, rospy_client.Time(0), period).success
    wait_until(lambda: api.sim_time_ns() == 25 * STEP_NS, 30, what='the world at 0.025 s')
    stepping.join(30)
    assert replies and replies[0].sim_time.to_nsec() == 25 * STEP_NS


PERIODS = 30
OVERSLEPT = 10  # the period the second run's controller sleeps through


@pytest.mark.parametrize('start', ['zero', 'clock'])
def test_lockstep_wakes_a_controller_that_slept_past_the_stop(ros, engine, api, rospy_client,
                                                              start):
    """roscpp's and rospy's Rate read the clock twice and sleep for the remainder counted from the
    second reading: when the stop's clock lands between the two (a client preempted there on a busy
    machine), or a command is lost in transport, the client sleeps one period past the stop the
    world waits at. The world then shows the clock a period ahead and stays where it is: the late
    command lands at the stop, the next (sent at once) at the next stop, and the run is bit for bit
    that of a controller on time, with no timeout. Jobs start at 0 ("now", as the book's client
    commands them) or at the clock last seen (as rospy's time gives it): both mean the world's
    time, also when the clock is shown ahead of it."""
    from rosgraph_msgs.msg import Clock
    clock_ns = []
    rospy_client.Subscriber('/clock', Clock, lambda msg: clock_ns.append(msg.clock.to_nsec()))
    start_sim(ros, engine, ['_paused:=true', '_lockstep:=true', '_lockstep_timeout:=60'])
    api.spawn_robot()
    period_ns = 10 * STEP_NS

    def run(overslept=None):
        """A PD controller in the book's shape (10 ms jobs starting now), from 0.010 s for PERIODS
        periods, sleeping through the period `overslept`; returns the joint where its last job
        ends, and at each wake-up how far the clock it woke on was ahead of the world."""
        api.reset_simulation()
        start_ns = api.step_simulation(10).sim_time.to_nsec()
        # The run starts on this run's clock, not the last one's still on its way.
        wait_until(lambda: clock_ns and clock_ns[-1] == start_ns, 30, interval=0.001,
                   what='the clock at %.3f s' % (start_ns * 1e-9))
        ahead = []
        for k in range(PERIODS):
            wake_ns = start_ns + (k + (k == overslept)) * period_ns
            wait_until(lambda: clock_ns and clock_ns[-1] >= wake_ns, 30, interval=0.001,
                       what='the clock at %.3f s' % (wake_ns * 1e-9))
            ahead.append(clock_ns[-1] - api.sim_time_ns())
            q, rate = api.joint()
            now = rospy_client.Time(0, clock_ns[-1] if start == 'clock' else 0)
            res = api.apply_joint_effort('joint1', 10.0 * (1.0 - q) - 3.0 * rate, now,
                                         rospy_client.Duration(0, period_ns))
            assert res.success, res.status_message
            if k == 0:
                api.unpause_physics()
        # Read where the world stops after the last job (the request waits for that stop).
        joint = api.joint()
        assert api.sim_time_ns() == start_ns + PERIODS * period_ns
        api.pause_physics()
        return joint, ahead

    on_time, on_time_ahead = run()
    late, late_ahead = run(overslept=OVERSLEPT)
    assert late == on_time
    # The late controller was woken by the clock shown a period ahead while the world stood at
    # the stop (it had not given up on the controller and gone on). A controller on time does not
    # need that clock, yet a machine at several times its cores' load can bring it: the stop's
    # clock still unwritten in the simulator's own queue when the wait runs out, this process seen
    # blocked meanwhile. It is harmless (the runs are equal, above) and at most a period ahead.
    assert late_ahead[OVERSLEPT] == period_ns
    assert set(on_time_ahead + late_ahead) <= {0, period_ns}, (on_time_ahead, late_ahead)
    print('wake-up clocks a controller on time saw: %d of %d periods' % (
        sum(1 for k, ahead in enumerate(on_time_ahead + late_ahead)
            if ahead and k != PERIODS + OVERSLEPT), 2 * PERIODS - 1))


def test_lockstep_holds_a_stop_clock_while_its_controller_is_between_two_readings(
        ros, engine, api, rospy_client):
    """roscpp's and rospy's Rate read the clock, then read it again and sleep the remainder counted
    from the second reading. A controller kept from running between the two (preempted on a busy
    machine; here it computes for 30 ms) must not see the next stop's clock move in between, or it
    sleeps a period past the stop: the stop's clock goes out only once its process rests. So at
    every wake-up its clock is the world's time, a period after the last, with no wake-up clock
    shown ahead and no timeout."""
    import time
    from rosgraph_msgs.msg import Clock
    clock_ns = []
    rospy_client.Subscriber('/clock', Clock, lambda msg: clock_ns.append(msg.clock.to_nsec()))
    start_sim(ros, engine, ['_paused:=true', '_lockstep:=true', '_lockstep_timeout:=60'])
    api.spawn_robot()
    period_ns = 10 * STEP_NS
    start_ns = api.step_simulation(10).sim_time.to_nsec()
    wait_until(lambda: clock_ns and clock_ns[-1] == start_ns, 30, interval=0.001,
               what='the clock at %.3f s' % (start_ns * 1e-9))
    woke = []  # (the clock seen on waking, the world's time then)
    period_start_ns = start_ns
    for k in range(PERIODS):
        woke.append((clock_ns[-1], api.sim_time_ns()))
        q, rate = api.joint()
        res = api.apply_joint_effort('joint1', 10.0 * (1.0 - q) - 3.0 * rate, rospy_client.Time(0),
                                     rospy_client.Duration(0, period_ns))
        assert res.success, res.status_message
        if k == 0:
            api.unpause_physics()
        first_ns = clock_ns[-1]
        busy_until = time.monotonic() + 0.03
        while time.monotonic() < busy_until:
            pass
        wake_ns = clock_ns[-1] + (period_start_ns + period_ns - first_ns)
        period_start_ns += period_ns
        wait_until(lambda: clock_ns[-1] >= wake_ns, 30, interval=0.001,
                   what='the clock at %.3f s' % (wake_ns * 1e-9))
    assert woke == [(start_ns + k * period_ns,) * 2 for k in range(PERIODS)]
    # And the world waits for the controller where its last job ended: it never gave up on it.
    assert api.sim_time_ns() == start_ns + PERIODS * period_ns


def test_lockstep_a_period_already_over_applies_nothing_and_the_world_waits_on_its_grid(
        ros, engine, api, rospy_client):
    """A controller behind the world (it started while the world ran free) commands a period
    that is over where the world is: nothing is applied, the reply says so, and the world waits
    for the period under way, instead of running the late job a period past its end for good
    (each later sample would then be read a period after its stamp). A period under way acts for
    what is left of it: the world stops on the controller's grid."""
    start_sim(ros, engine, ['_paused:=true', '_lockstep:=true', '_lockstep_timeout:=60'])
    api.spawn_robot()
    api.step_simulation(25)
    period = rospy_client.Duration(0, 10 * STEP_NS)
    over = api.apply_joint_effort('joint1', 0.5, rospy_client.Time(0, 10 * STEP_NS), period)
    assert over.success, over.status_message
    assert 'its period (start_time + duration) was over at sim time 0.025 s' in over.status_message
    under_way = api.apply_joint_effort('joint1', 0.5, rospy_client.Time(0, 20 * STEP_NS), period)
    assert under_way.success and 'nothing was applied' not in under_way.status_message
    api.unpause_physics()
    # Requests land where the world stops: at 0.030 s, the end of the period under way (started
    # now for its whole duration, either job would have run the world to 0.035 s).
    wait_until(lambda: api.sim_time_ns() >= 30 * STEP_NS, 30, what='the world at 0.030 s')
    assert api.sim_time_ns() == 30 * STEP_NS
