"""Lock-step with the tutorial's controller while other clients come and go (on one engine), and
when the controller exits (on every engine), over real ROS.

Only the controllers the lock-step serves hold the world: a command publisher, a `rostopic echo`
or any other client coming and going never does, and a controller whose process exits is let go
of at once. The tutorial's setting throughout: `_lockstep:=true` at the default max_update_rate
(real-time factor 1), the tutorial robot, `rosrun minimal_joint_controller
minimal_joint_controller`.

The world's pace is timed by the arrivals of /clock on this test's wall clock. Tests never assert
wall-clock speed: each compares a wait against the machine's own, measured the same way in the
same run. The clients' own cost is part of the machine's: each is a Python process that takes
seconds of CPU to start, which on a busy machine keeps the simulator and the controller waiting
for a core. So the clients' /clock gaps are set against those of their stand-ins, the same
commands run as often, whose peer is this test instead of the controller. On a busy machine this
test's own process is sometimes kept from reading for a second and more while the simulator
publishes on (its log says so, and the messages then arrive at once): what the world did is told
apart by the sim time that arrives right after a gap (world_gaps).
"""
import os
import re
import signal
import threading
import time

import pytest

from api_client import GazeboApi
from conftest import ENGINES, start_sim
from onedof_harness.private_ros import wait_until
from onedof_harness.process_rest import thread_states

CONTROLLER = ['rosrun', 'minimal_joint_controller', 'minimal_joint_controller']
PERIOD_S = 0.01  # the controller's period (100 Hz), of sim time and, at real-time factor 1, wall
ROUNDS = 8
# A /clock gap the clients may add to the machine's own before the world counts as held.
MARGIN_S = 0.05
# A gap that counts as a hold: a client that held the world stopped /clock for a second and more
# at most of its exits; a busy machine alone stops it for a few hundred ms now and then.
HOLD_S = 0.5
# How many holds the clients may have beyond those of their stand-ins: the machine alone puts a few
# anywhere.
HOLDS_BEYOND_STAND_INS_MOST = 2
# How long after a gap the messages that make up for it in sim time may arrive (a backlog read at
# once by a process that was kept from reading).
MADE_UP_WITHIN_S = 0.1
# How long the machine's own /clock gaps are measured before the controller is stopped.
OWN_S = 3.0
CLIENT_TIMEOUT_S = 120  # bounds a client that hangs; rostopic pub -1 itself takes 3 s and more
# How long the clients' span lasts past the last one's exit, in sim time: the controller ends the
# thread it started for a client up to a minute after the client has gone (rospy retries a dropped
# connection with growing waits before it sees its publisher gone), and a client that held the
# world did so when that thread ended.
LINGER_S = 75.0
# Bounds only a failure: how long /clock may stand still before the world counts as stuck. A
# span's sim time takes minutes, and on a busy machine the lock-stepped world runs at a fraction of
# real time, so a span is bounded by its progress, not by its length.
STALL_TIMEOUT_S = 120
# A test here lasts minutes of sim time, lock-stepped at real time: on a busy machine the world
# runs at a fraction of it, longer than the suite's bound per test.
pytestmark = pytest.mark.timeout(1800)
# The clients, each run ROUNDS times in a row (its k-th run's command): a command publisher to the
# controller, which then exits, and a subscriber to what the controller publishes. Each kind is a
# test of its own, so that a test's clients fit its time on a busy machine.
CLIENTS = {
    'rostopic_pub': lambda k: ['rostopic', 'pub', '-1', '/pos_cmd', 'std_msgs/Float64', '--',
                               '0.2' if k % 2 else '-0.2'],
    'rostopic_echo': lambda k: ['rostopic', 'echo', '-n', '1', '/jnt_pos'],
}
# Their stand-ins: the same commands on topics this test subscribes to (STAND_IN_COMMAND) and
# publishes, latched (STAND_IN_STATE), so that they start, connect, exchange a message and exit as
# the clients do, with this test in the controller's place.
STAND_IN_COMMAND = '/lockstep_stand_in/pos_cmd'
STAND_IN_STATE = '/lockstep_stand_in/jnt_pos'
STAND_INS = {
    'rostopic_pub': lambda k: ['rostopic', 'pub', '-1', STAND_IN_COMMAND, 'std_msgs/Float64', '--',
                               '0.2' if k % 2 else '-0.2'],
    'rostopic_echo': lambda k: ['rostopic', 'echo', '-n', '1', STAND_IN_STATE],
}


class StandInPeer:
    """This test as the stand-ins' peer: it subscribes to STAND_IN_COMMAND, counting what arrives,
    and publishes STAND_IN_STATE, latched."""

    def __init__(self, rospy):
        from std_msgs.msg import Float64
        self.commands = 0
        self._subscriber = rospy.Subscriber(STAND_IN_COMMAND, Float64, self._on_command)
        self._publisher = rospy.Publisher(STAND_IN_STATE, Float64, queue_size=1, latch=True)
        self._publisher.publish(Float64(0.0))

    def _on_command(self, _):
        self.commands += 1


class ClockArrivals:
    """Every /clock message: (wall time of its arrival here, monotonic, s; its sim time, ns)."""

    def __init__(self, rospy):
        from rosgraph_msgs.msg import Clock
        self._lock = threading.Lock()
        self._arrivals = []
        rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=10000)

    def _on_clock(self, msg):
        with self._lock:
            self._arrivals.append((time.monotonic(), msg.clock.to_nsec()))

    def arrivals(self):
        with self._lock:
            return list(self._arrivals)

    def latest(self):
        # Polled every few ms while the arrivals grow to tens of thousands: no copy of them.
        with self._lock:
            return self._arrivals[-1] if self._arrivals else (None, -1)

    def world_gaps(self):
        """(wall time it starts, its length, the world's part of it) of each gap between two
        arrivals. The world's part is what the sim time arriving within MADE_UP_WITHIN_S after it
        does not make up: none when the simulator published on while this process did not read
        (the backlog arrives at once), all of it when the world stood still (once more than 0.1 s
        behind its pace, the simulator goes on from the wall time it is at, making up nothing)."""
        arrivals = self.arrivals()
        gaps = []
        last = 0  # the last arrival within MADE_UP_WITHIN_S after the gap
        for i in range(len(arrivals) - 1):
            (start, start_ns), (end, _) = arrivals[i], arrivals[i + 1]
            last = max(last, i + 1)
            while last + 1 < len(arrivals) and arrivals[last + 1][0] <= end + MADE_UP_WITHIN_S:
                last += 1
            lost = (arrivals[last][0] - start) - (arrivals[last][1] - start_ns) * 1e-9
            gaps.append((start, end - start, max(0.0, min(end - start, lost))))
        return gaps

    def largest_gaps(self, windows):
        """For each (start, end) window of wall time, of the gaps that start in it: the largest
        world's part, and the largest gap as this process heard it."""
        gaps = self.world_gaps()
        largest = []
        for start, end in windows:
            inside = [(world, gap) for at, gap, world in gaps if start <= at <= end]
            largest.append((max((world for world, _ in inside), default=0.0),
                            max((gap for _, gap in inside), default=0.0)))
        return largest


def lockstepped_tutorial(ros, engine, rospy_client, sim_args=()):
    """The tutorial in lock-step: the simulator, the controller, the robot spawned once the
    controller looks for its joint; returns (simulator, controller, ClockArrivals) once the
    controller's joint has joined the lock-step."""
    sim = start_sim(ros, engine, ['_lockstep:=true'] + list(sim_args))
    clock = ClockArrivals(rospy_client)
    controller = ros.start(CONTROLLER, name='controller')
    ros.wait_until(lambda: 'cannot read joint joint1' in ros.log_text(controller), 60,
                   what='the controller to look for joint1')
    GazeboApi(rospy_client).spawn_robot()
    ros.wait_until(lambda: 'lock-step: joint1 is commanded by /minimal_joint_controller'
                   in ros.log_text(sim), 60, what='the controller to join the lock-step')
    return sim, controller, clock


# What the simulator logs when the lock-step held the world for its whole timeout: a controller's
# process that did not rest, or a controller that sent nothing.
HELD_LINES = ('the world waited', 'did not rest')
# What the simulator logs (at debug level) when it shows the clock ahead of a stop to wake a
# controller that slept past it.
WAKE_UP_LINE = 'to wake a controller that slept past the stop'
# How often (wall s) a wait reads the simulator's log for them.
LOG_LOOK_S = 1.0


def lockstep_lines(log):
    return '\n'.join(line for line in log.splitlines() if 'lock-step' in line)


def wait_for_sim_time(clock, target_ns, what, sim_log):
    """Waits until /clock has reached target_ns; fails if it stands still for STALL_TIMEOUT_S of
    wall time on the way, or as soon as the simulator's log (sim_log() reads it) says the
    lock-step held the world for its timeout: a world held at stop after stop still moves, too
    slowly for the test to end."""
    progress = {'ns': clock.latest()[1], 'at': time.monotonic(), 'log_read': time.monotonic()}

    def reached():
        now_ns = clock.latest()[1]
        if now_ns >= target_ns:
            return True
        if time.monotonic() - progress['log_read'] >= LOG_LOOK_S:
            progress['log_read'] = time.monotonic()
            log = sim_log()
            if any(line in log for line in HELD_LINES):
                raise AssertionError('the lock-step held the world at %.3f s of sim time, '
                                     'waiting for %s:\n%s' % (now_ns * 1e-9, what,
                                                              lockstep_lines(log)))
        if now_ns > progress['ns']:
            progress.update(ns=now_ns, at=time.monotonic())
        elif time.monotonic() - progress['at'] > STALL_TIMEOUT_S:
            raise AssertionError('/clock stood still at %.3f s for %d s (wall) waiting for %s' % (
                now_ns * 1e-9, STALL_TIMEOUT_S, what))
        return False
    # The stall check fails first; this bound is never reached while the world moves.
    wait_until(reached, float('inf'), interval=0.01, what=what)


def wait_for_clock_after(clock, moment, what):
    """Waits until a /clock message has arrived after the wall time `moment` (the gap that
    starts before it is then known)."""
    wait_until(lambda: clock.latest()[0] is not None and clock.latest()[0] > moment, 60,
               interval=0.005, what=what)


def run_in_a_row(ros, clock, command, client, sim_log, what):
    """Runs command(k) for k < ROUNDS, one after another, then waits for LINGER_S of sim time past
    the last one's exit; returns the span of wall time it took, from the first one's start until
    the first /clock past it. A client kind 'rostopic_echo' must have printed its message."""
    start = time.monotonic()
    for k in range(ROUNDS):
        args = command(k)
        result = ros.run(args, timeout=CLIENT_TIMEOUT_S)
        assert result.returncode == 0, '%s exited with %d:\n%s%s' % (
            ' '.join(args), result.returncode, result.stdout, result.stderr)
        if client == 'rostopic_echo':
            assert 'data: ' in result.stdout, result.stdout
    wait_for_sim_time(clock, clock.latest()[1] + round(LINGER_S * 1e9),
                      '%g s of sim time after the last of %s' % (LINGER_S, what), sim_log)
    wait_for_clock_after(clock, time.monotonic() + MADE_UP_WITHIN_S, 'the clock after ' + what)
    return start, time.monotonic()


# On one engine: whether the world waits for a client is the simulator loop's lock-step, the same
# over every engine (the engine only computes the steps between its stops); the lock-step's
# other cases, here and in test_lockstep.py, run on every engine.
@pytest.mark.parametrize('engine', ENGINES[:1], indirect=True)
@pytest.mark.parametrize('client', sorted(CLIENTS))
def test_clients_coming_and_going_never_hold_the_lockstepped_world(ros, engine, rospy_client,
                                                                    client):
    """ROUNDS stand-ins in a row (the client's command on a topic of this test's), then ROUNDS
    `rostopic pub -1 /pos_cmd` or `rostopic echo -n 1 /jnt_pos` in a row: from the first client's
    start until LINGER_S of sim time after the last one's exit, the world stops /clock for HOLD_S
    and more at most HOLDS_BEYOND_STAND_INS_MOST times more often than over the same stretch of
    the stand-ins. A client that held the world (its connection's thread in the controller ending
    and taking its runs with it, so that the controller never seemed to have run since its
    command) stopped /clock for a second and more at most of its exits. The largest gaps with the
    clients and with their stand-ins are printed: on a quiet machine they are within MARGIN_S of
    each other."""
    sim, controller, clock = lockstepped_tutorial(ros, engine, rospy_client)
    # The simulator's one debug line: each clock it shows ahead of a stop to wake a controller
    # that slept past it (WAKE_UP_LINE; in a failure's lock-step lines, with its sim time).
    from roscpp.srv import SetLoggerLevel
    rospy_client.ServiceProxy('/gazebo/set_logger_level', SetLoggerLevel)('ros.onedof_sim', 'debug')
    peer = StandInPeer(rospy_client)

    def sim_log():
        return ros.log_text(sim)
    stand_ins = run_in_a_row(ros, clock, STAND_INS[client], client, sim_log, 'the stand-ins')
    if client == 'rostopic_pub':
        assert peer.commands == ROUNDS, 'this test heard %d of the stand-ins\' %d commands' % (
            peer.commands, ROUNDS)
    clients = run_in_a_row(ros, clock, CLIENTS[client], client, sim_log, 'the clients')
    ros.check_running('the clients')  # the controller among them

    (clients_world, clients_heard), (stand_ins_world, stand_ins_heard) = \
        clock.largest_gaps([clients, stand_ins])
    gaps = clock.world_gaps()
    holds = [sum(1 for at, _, world in gaps if span[0] <= at <= span[1] and world >= HOLD_S)
             for span in (clients, stand_ins)]
    longer = ['over %d ms: %d and %d' % (1e3 * bound, *(
        sum(1 for at, _, world in gaps if span[0] <= at <= span[1] and world > bound)
        for span in (clients, stand_ins))) for bound in (0.05, 0.1)]
    hold_list = ', '.join('%.1f ms at %+.1f s' % (1e3 * world, at - stand_ins[0])
                          for at, _, world in gaps if world >= HOLD_S)
    figures = ('the world\'s largest /clock gap (wall) with the clients %.1f ms, with their '
               'stand-ins %.1f ms; the largest as this test heard them %.1f and %.1f ms; world '
               'gaps %s; holds of %g s and more: %d and %d (%s, from the first stand-in\'s '
               'start); %.0f s of clients, %.0f s of stand-ins' % (
                   1e3 * clients_world, 1e3 * stand_ins_world, 1e3 * clients_heard,
                   1e3 * stand_ins_heard, ', '.join(longer), HOLD_S, holds[0], holds[1],
                   hold_list or 'none', clients[1] - clients[0], stand_ins[1] - stand_ins[0]))
    log = sim_log()
    figures += '; clocks shown ahead to wake the controller: %d' % log.count(WAKE_UP_LINE)
    print('%s, %s: %s' % (engine, client, figures))
    for line in HELD_LINES:
        assert line not in log, lockstep_lines(log)
    assert holds[0] <= holds[1] + HOLDS_BEYOND_STAND_INS_MOST, \
        figures + '\n' + lockstep_lines(log)


def exited_in_proc(pid):
    """Whether /proc shows process pid exited: gone, or every thread of it exited (a zombie its
    parent has not reaped; its leader reads exited as soon as it ends, the others a little
    later)."""
    return all(state in ('Z', 'X', 'x') for state in thread_states(pid).values())


@pytest.mark.parametrize('signal_name', ['SIGKILL', 'SIGINT'])
def test_a_controller_that_exits_is_let_go_at_once(ros, engine, rospy_client, signal_name):
    """The controller stopped (SIGSTOP), so that the world stands at the stop where its last job
    ends, then killed (SIGKILL: it never unregisters) or interrupted as Ctrl-C does (SIGINT, and
    SIGCONT to act on it: it may command a few periods more while rospy shuts down). The world
    waits for it, however long ~lockstep_timeout, until its exit shows in /proc (a zombie that
    this test, its parent, has not reaped yet), then goes on at once. In sim time: the killed
    controller's joint is let go of at the stop the world stood at when it was stopped (a period
    later if its command for that stop was still on its way), where its last job ends. In wall
    time, against the machine's own: from the exit showing in /proc to /clock going past that stop
    takes at most a period more than the largest /clock gap while the controller ran, plus
    MARGIN_S."""
    sim, controller, clock = lockstepped_tutorial(ros, engine, rospy_client,
                                                  ['_lockstep_timeout:=600'])
    api = GazeboApi(rospy_client)
    with open('/proc/%d/cmdline' % controller.pid, 'rb') as f:
        assert b'minimal_joint_controller' in f.read()  # rosrun execs the node itself
    start = time.monotonic()
    wait_for_clock_after(clock, start + OWN_S + MADE_UP_WITHIN_S,
                         '%g s of the lock-stepped world' % OWN_S)
    own = clock.largest_gaps([(start, start + OWN_S)])[0][0]

    controller.stopped = True
    os.kill(controller.pid, signal.SIGSTOP)
    # A request lands where the world stops: the end of the job commanded last (or of the one
    # before, if the controller's last command is still on its way).
    stop_ns = api.sim_time_ns()
    if signal_name == 'SIGKILL':
        os.kill(controller.pid, signal.SIGKILL)
    else:
        os.kill(controller.pid, signal.SIGINT)
        os.kill(controller.pid, signal.SIGCONT)
    visible = wait_until(lambda: exited_in_proc(controller.pid) and time.monotonic(), 60,
                         interval=0.001, what='the controller\'s exit to show in /proc')
    controller.wait(timeout=60)
    assert not os.path.exists('/proc/%d' % controller.pid)

    let_go = re.escape('lock-step: the process of /minimal_joint_controller (pid %d) has exited; '
                       'the world goes on at sim time ' % controller.pid) + \
        r'([0-9.]+) s without joint1 until commanded again'
    found = ros.wait_until(lambda: re.search(let_go, ros.log_text(sim)), 60,
                           what='the simulator to let go of the controller')
    let_go_ns = round(float(found.group(1)) * 1e9)
    assert let_go_ns >= stop_ns
    if signal_name == 'SIGKILL':
        assert let_go_ns <= stop_ns + round(PERIOD_S * 1e9)
    # Let go of, the world runs free at real-time factor 1, publishing every step: a message's
    # sim time past the stop says when, at the latest, the world went on. The message least
    # delayed on its way here tells it best: a second of them.
    wait_until(lambda: clock.latest()[1] > let_go_ns + 10 ** 9, 60, interval=0.001,
               what='/clock a second past %.3f s' % (let_go_ns * 1e-9))
    went_on = min(t - (ns - let_go_ns) * 1e-9 for t, ns in clock.arrivals() if ns > let_go_ns)
    took = went_on - visible
    figures = ('the world went on %.1f ms (wall) after the exit showed in /proc; its largest '
               '/clock gap while the controller ran: %.1f ms' % (1e3 * took, 1e3 * own))
    print('%s, %s: %s' % (engine, signal_name, figures))
    assert took <= own + PERIOD_S + MARGIN_S, figures
    log = ros.log_text(sim)
    assert 'the world waited' not in log
    assert 'did not rest' not in log
    assert log.count('has exited') == 1


# The timeout of the stopped-controller test: long enough that the wait is told apart from the
# machine's delays, which at load 20 are far shorter than one more timeout.
STOPPED_TIMEOUT_S = 10


def test_a_stopped_controller_holds_the_world_for_the_timeout_once(ros, engine, rospy_client):
    """The controller stopped (SIGSTOP) and left stopped: the world waits ~lockstep_timeout of
    wall time from where it stood, in all, then says so once and goes on without the joint while
    the controller is still stopped. The wait for the stop's clock (which a stopped process,
    never resting, holds up) is part of that timeout, not a second one before it: the world goes
    on after at least one timeout and before two. Continued (SIGCONT), the controller commands
    again and its joint joins the lock-step again."""
    sim, controller, clock = lockstepped_tutorial(
        ros, engine, rospy_client, ['_lockstep_timeout:=%d' % STOPPED_TIMEOUT_S])
    joined = 'lock-step: joint1 is commanded by /minimal_joint_controller'
    waited = 'the world waited %d s (wall) at sim time ' % STOPPED_TIMEOUT_S
    api = GazeboApi(rospy_client)
    os.kill(controller.pid, signal.SIGSTOP)
    try:
        stopped_at = time.monotonic()
        stop_ns = api.sim_time_ns()
        wait_until(lambda: waited in ros.log_text(sim), 10 * STOPPED_TIMEOUT_S, interval=0.01,
                   what='the lock-step timeout line')
        took = time.monotonic() - stopped_at
        # Going on without it, the world runs free while the controller is still stopped.
        wait_until(lambda: clock.latest()[1] > stop_ns + 10 ** 9, 60, interval=0.01,
                   what='/clock a second past the stop, the controller stopped')
        log = ros.log_text(sim)
        assert log.count(waited) == 1, log
        # The world may have stood at the stop a moment before the controller was stopped,
        # waiting for its command: a second of room below.
        assert STOPPED_TIMEOUT_S - 1 <= took < 2 * STOPPED_TIMEOUT_S, \
            'the world went on %.1f s (wall) after the controller was stopped' % took
    finally:
        os.kill(controller.pid, signal.SIGCONT)
    ros.wait_until(lambda: ros.log_text(sim).count(joined) == 2, 60,
                   what='the continued controller to join the lock-step again')
    assert controller.poll() is None
