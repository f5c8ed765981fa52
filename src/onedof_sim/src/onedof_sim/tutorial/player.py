"""The main job: plays the tutorial headless on a private ROS graph and writes what a student would
look at. The steps are the tutorial's: launch the simulator with the robot, run the controller,
command 1.0 then 2.0, bring the arm upright (0), insert the cafe table at x = 0.85, command 2.5.
Each phase lasts a fixed span of sim time; the recorder keeps every sample for the plots, the CSV
and the per-phase figures.

By default the simulator runs in lock-step with the controller (it waits for the controller's
command at the end of every period) and the player advances it phase by phase with
/gazebo/step_simulation, each command taken before its phase starts: the figures are the
physics' alone, the same on every run however busy the machine. The controller's first period
runs on its initial command 0, before the player has commanded anything, and it starts after one
period of the arm at rest (sim time 0 is no valid time to a ROS node): the phases start at 0.02 s. With free_run the simulator paces itself at a real-time factor and the
controller samples it over the network as a real robot would be, missed periods included.

Then the same phases play again through the in-simulator PID (the book's gazebo_ros_control
robot and YAML, effort_controllers/JointPositionController), on a paused world stepped phase by
phase, and each phase's figure shows both controllers (what the integral term does to the droop).
"""
import collections
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

import yaml

from onedof_harness.private_ros import PrivateRos
from onedof_sim.tools.plot import held_window
from onedof_sim.tutorial import physics
from onedof_sim.tutorial.rviz_view import RvizView

Phase = collections.namedtuple('Phase', 'name command before')

TABLE_X = 0.85
SPAWN_TABLE = ['rosrun', 'gazebo_ros', 'spawn_model', '-database', 'cafe_table', '-sdf',
               '-model', 'cafe_table', '-x', str(TABLE_X)]
PHASES = (
    Phase('command_1.0', 1.0, None),
    Phase('command_2.0', 2.0, None),
    Phase('upright_0.0', 0.0, None),
    Phase('table_2.5', 2.5, SPAWN_TABLE),
)
DEFAULT_TIME_STEP = 0.001  # the simulators' default step, s
CONTROL_PERIOD = 0.01      # minimal_joint_controller's default 100 Hz
CONTROLLER_NODE = '/minimal_joint_controller'
JOINT = 'joint1'
# Wall seconds the lock-stepped simulator waits for a silent controller: far beyond any period's
# work on a loaded machine, so that it never gives up on a live controller; a dead one is
# noticed by its exit.
LOCKSTEP_TIMEOUT = 30
RECORDED_TOPICS = ('pos_cmd', 'jnt_pos', 'jnt_vel', 'jnt_trq')


def seconds(ns):
    """Seconds from integer nanoseconds, rounded as rospy's Time.to_sec() rounds them."""
    return float(ns // 1000000000) + float(ns % 1000000000) / 1e9


def say(text):
    print('[tutorial] ' + text, flush=True)


def joint_state_samples(msg, joint=JOINT):
    """[(topic, sim time, value)] of a sensor_msgs/JointState: the joint's position, velocity and
    effort as jnt_pos, jnt_vel and jnt_trq, at the header stamp."""
    if joint not in msg.name:
        return []
    index = msg.name.index(joint)
    t = msg.header.stamp.to_sec()
    return [(topic, t, values[index]) for topic, values in
            (('jnt_pos', msg.position), ('jnt_vel', msg.velocity), ('jnt_trq', msg.effort))
            if index < len(values)]


def controller_state_samples(msg):
    """[(topic, sim time, value)] of a control_msgs/JointControllerState: the process value and
    its rate as jnt_pos and jnt_vel, the controller's effort command as jnt_trq, at the stamp."""
    t = msg.header.stamp.to_sec()
    return [('jnt_pos', t, msg.process_value), ('jnt_vel', t, msg.process_value_dot),
            ('jnt_trq', t, msg.command)]


class Recorder:
    """Keeps (sim time, value) of what the tutorial plots: pos_cmd as the player commands it, and
    jnt_pos, jnt_vel and jnt_trq as a controller reports them, each at the sim time its sample was
    taken (the header stamp: the Float64 topics carry no time, and the time of reception says
    nothing when the simulator runs faster than real time)."""

    def __init__(self):
        self.samples = {topic: [] for topic in RECORDED_TOPICS}

    def add(self, samples):
        for topic, t, value in samples:
            self.samples[topic].append((t, value))

    def command(self, t, value):
        self.samples['pos_cmd'].append((t, value))

    def latest(self):
        """Sim time of the newest joint sample (-inf before the first)."""
        return self.samples['jnt_pos'][-1][0] if self.samples['jnt_pos'] else -math.inf

    def between(self, topic, start, end):
        return [(t, v) for t, v in self.samples[topic] if start <= t < end]

    def series(self, start=-math.inf, end=math.inf, origin=0.0):
        """{topic: (times since origin, values)} of the samples in [start, end), each topic led
        by its value held at `start` (pos_cmd is published once per phase, before some)."""
        series = {}
        for topic in RECORDED_TOPICS:
            samples = list(self.samples[topic])  # one snapshot: the callbacks keep appending
            times, values = held_window([t for t, _ in samples], [v for _, v in samples],
                                        start, end)
            series[topic] = ([t - origin for t in times], values)
        return series


class JointStatesRecorder(Recorder):
    """The rospy controller's /joint_states, every message (one per control period)."""

    def __init__(self, rospy):
        super().__init__()
        from sensor_msgs.msg import JointState
        self.subscriber = rospy.Subscriber(
            '/joint_states', JointState, lambda msg: self.add(joint_state_samples(msg)),
            queue_size=100000)

    def connected(self):
        return self.subscriber.get_num_connections() > 0


class Rosout:
    """The log lines of some nodes (/rosout): the controller's for each command it takes, the
    simulator's when a controller joins the lock-step. They tell the player when to go on."""

    COMMAND_TAKEN = 'received value of pos_cmd is: '
    JOINED = 'lock-step: %s is commanded by %s' % (JOINT, CONTROLLER_NODE)

    def __init__(self, ros, rospy):
        from rosgraph_msgs.msg import Log
        self.wait_until = ros.wait_until
        self.lines = []
        self.subscriber = rospy.Subscriber('/rosout', Log, self._on_log, queue_size=1000)

    def connected(self, node):
        """Whether the node's /rosout reaches this subscriber."""
        return any(getattr(connection, 'callerid_pub', None) == node
                   for connection in list(self.subscriber.impl.connections))

    def _on_log(self, msg):
        self.lines.append((msg.name, msg.msg))

    def commands_taken(self):
        return [float(line[len(self.COMMAND_TAKEN):]) for node, line in list(self.lines)
                if node == CONTROLLER_NODE and line.startswith(self.COMMAND_TAKEN)]

    def wait_for_command_taken(self, value, taken_before, timeout=60):
        def taken():
            commands = self.commands_taken()
            return len(commands) > taken_before and abs(commands[-1] - value) < 1e-9
        self.wait_until(taken, timeout,
                        what='the controller to log that it took pos_cmd %g' % value)

    def wait_for_join(self, timeout=60):
        self.wait_until(lambda: any(node == '/gazebo' and line.startswith(self.JOINED)
                               for node, line in list(self.lines)), timeout,
                   what='the controller to join the lock-step')


def package_path(package):
    import rospkg
    return rospkg.RosPack().get_path(package)


# Every file the job writes into its output folder, beside logs/ (for every phase, whichever
# phases a run plays): what a run removes before it writes, so that nothing of an earlier run
# stays beside its outputs, and nothing else of a folder the user named.
SCREENSHOT = 'rviz_final.png'
WHOLE_RUN_OUTPUTS = ('tutorial.png', 'samples.csv', SCREENSHOT, 'summary.md', 'summary.json',
                     'in_sim_samples.csv')
PHASE_OUTPUTS = ('phase%d_%s.png', 'phase%d_%s_pd_vs_pid.png')


def job_outputs():
    return list(WHOLE_RUN_OUTPUTS) + [pattern % (number, phase.name) for pattern in PHASE_OUTPUTS
                                      for number, phase in enumerate(PHASES, 1)]


def clear_outputs(output):
    """Removes from `output` what a run of the job writes there (job_outputs() and logs/),
    nothing else: the folder may be the user's own."""
    for name in job_outputs():
        try:
            os.remove(os.path.join(output, name))
        except FileNotFoundError:
            pass
    shutil.rmtree(os.path.join(output, 'logs'), ignore_errors=True)


class MissingOutputs(RuntimeError):
    """The run wrote every output but these: {name: why it is missing}."""

    def __init__(self, missing):
        self.missing = missing
        super().__init__('; '.join('%s is missing: %s' % item for item in missing.items()))


def pd_prediction(phase, settled):
    """(predicted angle, predicted holding torque) of the rospy PD controller: where
    Kp (c - q) + m g d sin q = 0; on the table, at rest (rate 0), Kp times the remaining error."""
    if phase.before is SPAWN_TABLE:
        return physics.table_contact_angle(TABLE_X), physics.KP * (phase.command - settled)
    predicted = physics.settled_angle(phase.command)
    return predicted, -physics.gravity_torque(predicted)


def pid_prediction(gains):
    """The prediction function of a PID with these gains (p, i_clamp_max as ros_control reads
    them): the integral removes the droop, the link settles at the command holding gravity's
    torque; on the table the integral winds up to its clamp, so the torque is p times the
    remaining error plus i_clamp_max."""
    def predict(phase, settled):
        if phase.before is SPAWN_TABLE:
            return (physics.table_contact_angle(TABLE_X),
                    gains['p'] * (phase.command - settled) + gains['i_clamp_max'])
        return phase.command, -physics.gravity_torque(phase.command)
    return predict


def phase_summary(phase, recorder, start, end, expected_samples=None, predict=pd_prediction):
    """The phase's row of the summary from the recorder's samples in [start, end): settled angle,
    overshoot, settling time, holding torque against `predict`'s closed form. With
    expected_samples, a different count of position samples is an error (a lost sample)."""
    positions = recorder.between('jnt_pos', start, end)
    torques = recorder.between('jnt_trq', start, end)
    if len(positions) < 2 or len(torques) < 2:
        raise RuntimeError('phase %s recorded %d positions and %d torques: is the controller '
                           'running?' % (phase.name, len(positions), len(torques)))
    if expected_samples is not None and len(positions) != expected_samples:
        raise RuntimeError('phase %s recorded %d samples, not one per sampling period (%d)'
                           % (phase.name, len(positions), expected_samples))
    metrics = physics.step_metrics([t for t, _ in positions], [q for _, q in positions],
                                   start_value=positions[0][1])
    metrics['holding_torque'] = physics.tail_mean([t for t, _ in torques], [u for _, u in torques])
    predicted, metrics['predicted_torque'] = predict(phase, metrics['settled'])
    metrics['met_table'] = ('tip rim at x = %.3f m, z = %.3f m' % physics.tip_rim(
        metrics['settled'])) if phase.before is SPAWN_TABLE else ''
    metrics.update(name=phase.name, command=phase.command, predicted=predicted,
                   samples=len(positions))
    return metrics


SUMMARY_COLUMNS = (
    ('phase', 'name', '%s'), ('command (rad)', 'command', '%.2f'),
    ('settled (rad)', 'settled', '%.4f'), ('predicted (rad)', 'predicted', '%.4f'),
    ('overshoot (rad)', 'overshoot', '%.4f'), ('settling time (s)', 'settling_time', '%.2f'),
    ('holding torque (N m)', 'holding_torque', '%.3f'),
    ('predicted torque (N m)', 'predicted_torque', '%.3f'), ('met the table', 'met_table', '%s'))


def summary_table(rows):
    lines = ['| ' + ' | '.join(title for title, _, _ in SUMMARY_COLUMNS) + ' |',
             '|' + '---|' * len(SUMMARY_COLUMNS)]
    for row in rows:
        lines.append('| ' + ' | '.join(fmt % row[key] for _, key, fmt in SUMMARY_COLUMNS) + ' |')
    return lines


def summary_markdown(rows, physics_engine, free_run=False, in_sim_rows=()):
    lines = ['# Tutorial summary (%s engine, %s)'
             % (physics_engine, 'free-running' if free_run else 'lock-step'), '',
             'Predicted: where Kp (c - q) + m g d sin q = 0; with the table, the angle at which '
             'the link first touches the table top. Settling: within 0.02 rad of the settled '
             'angle. Times are sim time.', ''] + summary_table(rows)
    if in_sim_rows:
        lines += ['', '## The same phases through the in-simulator PID', '',
                  'effort_controllers/JointPositionController with the book\'s gains '
                  '(one_dof_ctl_params.yaml), run inside the simulator\'s step and sampled from '
                  'its state topic. Predicted: the command itself (the integral term removes '
                  'the droop) holding m g d sin c; on the table, p times the remaining error '
                  'plus the integral at its clamp.', ''] + summary_table(in_sim_rows)
    return '\n'.join(lines) + '\n'


class LockstepRun:
    """Advances the lock-stepped simulator phase by phase: each command is published while the
    world stands, taken by the controller (its log line), then the world steps through the phase
    and answers once the controller has acted at the phase's end. A phase is the periods in which
    the controller holds its command: from the period after the world stood to the one at the
    phase's end, times in integer nanoseconds so that every run draws the same edges."""

    def __init__(self, ros, rospy, recorder, pos_cmd):
        from onedof_sim.srv import StepSimulation
        self.wait_until = ros.wait_until
        from gazebo_msgs.srv import GetPhysicsProperties
        self.rospy = rospy
        self.recorder = recorder
        self.pos_cmd = pos_cmd
        self.rosout = Rosout(ros, rospy)
        self.step_service = rospy.ServiceProxy('/gazebo/step_simulation', StepSimulation)
        self.time_step = rospy.ServiceProxy('/gazebo/get_physics_properties',
                                            GetPhysicsProperties)().time_step
        self.now_ns = 0
        self.period_ns = int(round(CONTROL_PERIOD * 1e9))

    def before_controller(self):
        self.wait_until(lambda: self.rosout.connected('/gazebo'), 60,
                        what='the simulator\'s /rosout')
        # One period without a controller (the arm upright and at rest, no torque): ROS clients
        # have no valid time at sim time 0, so the controller starts on a time the world holds.
        self.now_ns = self.step(int(round(CONTROL_PERIOD / self.time_step)))

    def start(self):
        # The controller's first period, on its initial command: with it the controller joins
        # the lock-step (the simulator says so), and the world waits for it from then on.
        self.rosout.wait_for_join()
        self.wait_until(lambda: self.rosout.connected(CONTROLLER_NODE), 60,
                   what='the controller\'s /rosout')

    def step(self, steps):
        say('rosservice call /gazebo/step_simulation "steps: %d"' % steps)
        reply = self.step_service(steps)
        if not reply.success:
            raise RuntimeError('step_simulation: ' + reply.status_message)
        return reply.sim_time.to_nsec()

    def refresh(self):
        """One more control period at the final pose, after the phases: the world stands between
        steps, so an rviz started after the phases gets the controller's joint state (its
        transforms) and the simulator's markers only from a step."""
        self.now_ns = self.step(int(round(CONTROL_PERIOD / self.time_step)))

    def phase(self, command, duration):
        """Runs one phase; returns its (start, end) in sim time."""
        taken_before = len(self.rosout.commands_taken())
        self.pos_cmd.publish(self.pos_cmd.data_class(command))
        self.rosout.wait_for_command_taken(command, taken_before)
        start = seconds(self.now_ns + self.period_ns)
        self.recorder.command(start, command)
        self.now_ns = self.step(int(round(duration / self.time_step)))
        end = seconds(self.now_ns + self.period_ns)
        # Every sample of the phase is in once the one taken at its end is.
        self.wait_until(lambda: self.recorder.latest() >= seconds(self.now_ns), 60,
                   what='the controller\'s samples up to %.2f s' % seconds(self.now_ns))
        return start, end


class FreeRun:
    """Lets the simulator run at its pace; a phase is the sim time between a command and the end
    of its duration, as a student lives it."""

    def __init__(self, ros, rospy, recorder, pos_cmd):
        self.wait_until = ros.wait_until
        self.rospy = rospy
        self.recorder = recorder
        self.pos_cmd = pos_cmd

    def before_controller(self):
        pass

    def refresh(self):
        """Nothing: the free-running world goes on publishing its pose and markers."""

    def start(self):
        from std_srvs.srv import Empty
        say('rosservice call /gazebo/unpause_physics')
        self.rospy.ServiceProxy('/gazebo/unpause_physics', Empty)()
        self.wait_until(lambda: self.recorder.samples['jnt_pos'], 60,
                        what='the controller on jnt_pos')

    def phase(self, command, duration):
        start = self.rospy.get_time()
        self.pos_cmd.publish(self.pos_cmd.data_class(command))
        self.recorder.command(start, command)
        end = start + duration
        self.wait_until(lambda: self.rospy.get_time() >= end, duration * 20 + 30,
                   what='%.0f s of sim time' % duration)
        return start, end


def run_before(ros, phase):
    """What the student does before the phase's command (the table's spawn), if anything."""
    if phase.before:
        say(' '.join(phase.before))
        result = ros.run(phase.before)
        if result.returncode != 0:
            raise RuntimeError('%s failed:\n%s%s' % (' '.join(phase.before),
                                                    result.stdout, result.stderr))


def play_phases(ros, run, recorder, phases, phase_duration, command_topic, sample_period,
                predict=pd_prediction):
    """Plays the phases with `run` (LockstepRun, FreeRun or InSimRun), as the student types them;
    returns their summary rows, each phase's series since its command, and each one's (start,
    end) in sim time.
    With a sample_period, each phase must have recorded one sample per period."""
    rows, series, spans = [], [], []
    for phase in phases:
        run_before(ros, phase)
        say('rostopic pub %s std_msgs/Float64 %.1f   (%.0f s of sim time)'
            % (command_topic, phase.command, phase_duration))
        phase_wall = time.monotonic()
        start, end = run.phase(phase.command, phase_duration)
        row = phase_summary(phase, recorder, start, end, predict=predict,
                            expected_samples=sample_period and round((end - start) / sample_period))
        say('  settled at %.4f rad (predicted %.4f), holding %.3f N m; %.1f s of sim time '
            'in %.1f s of wall time' % (row['settled'], row['predicted'], row['holding_torque'],
                                        end - start, time.monotonic() - phase_wall))
        rows.append(row)
        series.append(recorder.series(start, end, origin=start))
        spans.append((start, end))
    return rows, series, spans


# The in-simulator run: the book's gazebo_ros_control robot and controllers (issue 13).
IN_SIM_NAMESPACE = '/one_DOF_robot'
IN_SIM_CONTROLLER = 'joint1_position_controller'
IN_SIM_CONTROLLERS = ('joint_state_controller', IN_SIM_CONTROLLER)
IN_SIM_COMMAND = '%s/%s/command' % (IN_SIM_NAMESPACE, IN_SIM_CONTROLLER)
IN_SIM_STATE = '%s/%s/state' % (IN_SIM_NAMESPACE, IN_SIM_CONTROLLER)
# The integral brings the link to its command slowly (upright after 2.0 is the slowest: the
# integral holding 2.0 against gravity unwinds over some 30 s): this long settles every phase
# within 1e-3 rad.
IN_SIM_PHASE_DURATION = 40.0
# Sim seconds between the in-sim samples: the world is stepped this much at a time and the
# controller's newest state of each step taken (its state publisher keeps only the newest).
IN_SIM_SAMPLE_PERIOD = 0.05
STATE_PERIOD = 0.01  # ros_controllers publish the state on every tenth 1 ms update


def book_pid_gains():
    """The position controller's pid gains from the book's YAML, as the simulator reads them."""
    with open(os.path.join(package_path('minimal_robot_description'), 'control_config',
                           'one_dof_ctl_params.yaml')) as f:
        config = yaml.safe_load(f)
    return config[IN_SIM_NAMESPACE.strip('/')][IN_SIM_CONTROLLER]['pid']


def newest_sample_of_step(states, after_ns, until_ns):
    """The newest of the (stamp ns, message) states in (after_ns, until_ns], None if none: the one
    sample a step from after_ns to until_ns keeps, whichever others got through."""
    inside = [(stamp, msg) for stamp, msg in states if after_ns < stamp <= until_ns]
    return max(inside, key=lambda pair: pair[0]) if inside else None


def bus_messages_received(bus_stats, topic):
    """Messages a roscpp node's subscription to `topic` has read, from its slave API's
    getBusStats answer. roscpp answers the stats themselves, without rospy's [code, message]
    before them: [publish stats, subscribe stats, ...], the subscribe stats as
    [topic, [[connection, bytes, messages, drops, connected], ...]]."""
    subscribe_stats = bus_stats[1]
    return sum(connection[2] for name, connections in subscribe_stats if name == topic
               for connection in connections)


class InSimRun:
    """Advances a paused world with in-simulator controllers phase by phase: each command is
    published on the controller's command topic while the world stands, read by the simulator
    before the world moves again, then the world steps through the phase IN_SIM_SAMPLE_PERIOD at
    a time and the controller's newest state of each step is recorded. Controllers inside the
    step need no lock-step: nothing outside the simulator takes part in a period."""

    def __init__(self, ros, rospy, recorder):
        import threading
        import xmlrpc.client
        from control_msgs.msg import JointControllerState
        from controller_manager_msgs.srv import ListControllers
        from gazebo_msgs.srv import GetPhysicsProperties
        from onedof_sim.srv import StepSimulation
        from std_msgs.msg import Float64
        self.ros = ros
        self.recorder = recorder
        self.states = []  # (stamp ns, JointControllerState), as they arrive
        self.arrived = threading.Condition()
        self.state_subscriber = rospy.Subscriber(IN_SIM_STATE, JointControllerState,
                                                 self._on_state, queue_size=1000)
        self.command_pub = rospy.Publisher(IN_SIM_COMMAND, Float64, queue_size=1, latch=True)
        self.step_service = rospy.ServiceProxy('/gazebo/step_simulation', StepSimulation)
        self.list_controllers = rospy.ServiceProxy(
            IN_SIM_NAMESPACE + '/controller_manager/list_controllers', ListControllers)
        self.time_step = rospy.ServiceProxy('/gazebo/get_physics_properties',
                                            GetPhysicsProperties)().time_step
        _, _, simulator_uri = ros.master().lookupNode('/tutorial_player', '/gazebo')
        self.simulator = xmlrpc.client.ServerProxy(simulator_uri)
        self.now_ns = 0

    def _on_state(self, msg):
        with self.arrived:
            self.states.append((msg.header.stamp.to_nsec(), msg))
            self.arrived.notify_all()

    def wait_for_controllers(self, timeout=60):
        """Until the spawner has both controllers running and our topics are connected."""
        def running():
            listed = {c.name: c.state for c in self.list_controllers().controller}
            return all(listed.get(name) == 'running' for name in IN_SIM_CONTROLLERS)
        self.ros.wait_for_service(IN_SIM_NAMESPACE + '/controller_manager/list_controllers', 60)
        self.ros.wait_until(running, timeout, what='the spawner to start %s'
                            % ' and '.join(IN_SIM_CONTROLLERS))
        self.ros.wait_until(lambda: self.state_subscriber.get_num_connections() > 0 and
                            self.command_pub.get_num_connections() > 0, timeout,
                            what='the connections to %s and %s' % (IN_SIM_STATE, IN_SIM_COMMAND))

    def commands_received(self):
        return bus_messages_received(self.simulator.getBusStats('/tutorial_player'),
                                     IN_SIM_COMMAND)

    def step(self, steps):
        reply = self.step_service(steps)
        if not reply.success:
            raise RuntimeError('step_simulation: ' + reply.status_message)
        return reply.sim_time.to_nsec()

    def wait_for_state(self, after_ns, until_ns, timeout=60):
        deadline = time.monotonic() + timeout
        with self.arrived:
            while True:
                newest = newest_sample_of_step(self.states, after_ns, until_ns)
                if newest and newest[0] > until_ns - STATE_PERIOD * 1e9:
                    return newest
                self.ros.check_running('the controller state at %.3f s' % seconds(until_ns))
                if time.monotonic() > deadline:
                    raise TimeoutError('timed out after %.0f s waiting for %s at %.3f s'
                                       % (timeout, IN_SIM_STATE, seconds(until_ns)))
                self.arrived.wait(0.5)

    def phase(self, command, duration):
        """Runs one phase; returns its (start, end) in sim time."""
        received_before = self.commands_received()
        self.command_pub.publish(self.command_pub.data_class(command))
        self.ros.wait_until(lambda: self.commands_received() > received_before, 60, interval=0.01,
                            what='the simulator to read command %g' % command)
        # Read is not yet taken: the command's callback is queued on the simulator's spinner. A
        # service call queued after it answers once the callback has been dequeued.
        self.list_controllers()
        start = seconds(self.now_ns)
        self.recorder.command(start, command)
        chunk = int(round(IN_SIM_SAMPLE_PERIOD / self.time_step))
        with self.arrived:
            self.states = []
        for _ in range(int(round(duration / IN_SIM_SAMPLE_PERIOD))):
            before_ns, self.now_ns = self.now_ns, self.step(chunk)
            stamp_ns, state = self.wait_for_state(before_ns, self.now_ns)
            if state.set_point != command:
                raise RuntimeError('%s reports set point %g at %.3f s, not the command %g'
                                   % (IN_SIM_STATE, state.set_point, seconds(stamp_ns), command))
            self.recorder.add(controller_state_samples(state))
            with self.arrived:
                self.states = []
        return start, seconds(self.now_ns)


def play_in_sim(log_dir, physics_engine, phase_duration=IN_SIM_PHASE_DURATION, phases=PHASES):
    """The tutorial's phases through the in-simulator PID, launched as the book does it (our
    minimal_robot_in_sim_w_jnt_ctl.launch: the simulator, the robot with gazebo_ros_control's tag,
    the book's YAML and the spawner), paused and stepped. Runs in a process of its own (rospy
    inits once per process). Returns (rows, [per-phase series since each command], the whole
    run's series)."""
    with PrivateRos(log_dir=log_dir, use_sim_time=True) as ros:
        launch = ['roslaunch', 'minimal_robot_description', 'minimal_robot_in_sim_w_jnt_ctl.launch',
                  'physics:=' + physics_engine, 'paused:=true']
        say(' '.join(launch))
        ros.start(launch, name='launch_in_sim')
        ros.adopt_environment()
        import rospy
        rospy.init_node('tutorial_player', disable_signals=True)
        recorder = Recorder()
        ros.wait_for_service('/gazebo/get_physics_properties', timeout=60)
        run = InSimRun(ros, rospy, recorder)
        run.wait_for_controllers()
        predict = pid_prediction(book_pid_gains())
        rows, series, _ = play_phases(ros, run, recorder, phases, phase_duration,
                                      IN_SIM_COMMAND, IN_SIM_SAMPLE_PERIOD, predict)
        rospy.signal_shutdown('in-sim tutorial finished')
    return rows, series, recorder.series()


def compared_panels(pd_series, pid_series):
    """One figure's panels [(ylabel, {label: (times, values)})]: the command and each controller's
    position above, each controller's torque below, labelled by controller, each panel by its
    unit (plot.unit_panels)."""
    from onedof_sim.tools import plot
    labelled = (('rospy PD', pd_series), ('in-sim PID', pid_series))
    # The controllers first in both panels: each keeps its colour from one panel to the other.
    series = {'%s jnt_pos' % label: data['jnt_pos'] for label, data in labelled}
    series['pos_cmd'] = pid_series['pos_cmd']
    series.update(('%s jnt_trq' % label, data['jnt_trq']) for label, data in labelled)
    return plot.unit_panels(series)


def play_in_sim_beside(output, physics_engine, phase_duration, phases, pd_rows, pd_series,
                       pd_phase_duration):
    """Plays the phases through the in-simulator PID (in a process of its own: this one's rospy
    belongs to the first graph; see in_sim_main) and draws each phase's figure beside the rospy
    PD controller's; writes in_sim_samples.csv; returns the in-sim rows."""
    from onedof_sim.tools import plot
    result_path = os.path.join(output, 'logs', 'in_sim', 'result.json')
    os.makedirs(os.path.dirname(result_path), exist_ok=True)
    # A process of our Python started as play_tutorial is: the same imports (onedof_sim's
    # generated messages with it), its own rospy node, its log lines on our output.
    subprocess.run([sys.executable, '-m', 'onedof_sim.tutorial.player', result_path,
                    physics_engine, repr(phase_duration), str(len(phases))], check=False)
    try:
        with open(result_path) as f:
            result = json.load(f)
    except (OSError, ValueError) as error:
        raise RuntimeError('the in-sim run left no result (%s)' % error) from None
    if 'error' in result:
        raise RuntimeError('in-sim run: ' + result['error'])
    rows, series, whole = result['rows'], result['series'], result['whole']
    for number, (phase, pd_row, pd, pid) in enumerate(zip(phases, pd_rows, pd_series, series), 1):
        plot.write_panels_figure(
            compared_panels(pd, pid),
            os.path.join(output, 'phase%d_%s_pd_vs_pid.png' % (number, phase.name)),
            title='%s (%s): rospy PD settles at %.3f, in-sim PID at %.3f'
                  % (phase.name, physics_engine, pd_row['settled'], rows[number - 1]['settled']),
            xlabel='sim time since the command (s); the rospy PD\'s phase ends at %g s, its '
                   'last values drawn held after' % pd_phase_duration, until=phase_duration,
            zoom=True)
    plot.write_csv(whole, os.path.join(output, 'in_sim_samples.csv'))
    return rows


def in_sim_main(argv):
    """`python -m onedof_sim.tutorial.player RESULT_JSON PHYSICS DURATION PHASES`: play_in_sim
    of the first PHASES phases, its logs beside RESULT_JSON, its rows and series (or the error)
    into it."""
    result_path, physics_engine, phase_duration, phase_count = argv
    try:
        rows, series, whole = play_in_sim(os.path.dirname(result_path), physics_engine,
                                          float(phase_duration), PHASES[:int(phase_count)])
        result = dict(rows=rows, series=series, whole=whole)
    except (RuntimeError, TimeoutError) as error:
        result = dict(error=str(error))
    with open(result_path, 'w') as f:
        json.dump(result, f)


def play(output, physics_engine, phase_duration=5.0, screenshot=True, free_run=False,
         real_time_factor=1.0, phases=PHASES, in_sim_phase_duration=IN_SIM_PHASE_DURATION):
    """Plays the tutorial's `phases` (a leading part of PHASES: each starts where the one before
    left the arm), in lock-step unless free_run (then paced at real_time_factor), then (unless
    in_sim_phase_duration is 0) the same phases through the in-simulator PID; returns the
    rospy controller's per-phase summary rows. Starts by clearing what an earlier run wrote
    into `output` (clear_outputs). Raises with the reason on failure; raises MissingOutputs after
    writing every other output when the rviz screenshot could not be taken."""
    from onedof_sim.tools import plot
    os.makedirs(output, exist_ok=True)
    clear_outputs(output)
    log_dir = os.path.join(output, 'logs')
    missing = {}  # {output name: why it is missing}
    wall_start = time.monotonic()
    # /use_sim_time before any node starts, as Gazebo's launch files do, so that every node
    # (this one included) runs on sim time from its first message.
    with PrivateRos(log_dir=log_dir, use_sim_time=True) as ros:
        say('roscore on %s (logs in %s)' % (ros.master_uri, log_dir))
        # Paused until the controller runs: the upright pose is an unstable balance, which one
        # engine holds exactly and the other loses to round-off before a late controller starts.
        launch = ['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch',
                  'physics:=' + physics_engine, 'paused:=true']
        if free_run:
            if real_time_factor != 1.0:
                launch.append('max_update_rate:=%g' % (real_time_factor / DEFAULT_TIME_STEP))
        else:
            launch += ['lockstep:=true', 'lockstep_timeout:=%g' % LOCKSTEP_TIMEOUT]
        say(' '.join(launch))
        ros.start(launch, name='launch_simulator')
        ros.adopt_environment()
        import rospy
        rospy.init_node('tutorial_player', disable_signals=True)
        from gazebo_msgs.srv import GetModelState
        ros.wait_for_service('/gazebo/get_model_state', timeout=60)
        model_state = rospy.ServiceProxy('/gazebo/get_model_state', GetModelState)
        ros.wait_until(lambda: model_state('one_DOF_robot', '').success, 60,
                       what='one_DOF_robot to be spawned')
        # rviz (software rendering) starts while the simulator is paused and is up before the
        # phases run, so its start-up never takes the CPU from the controller.
        # rviz may die (see rviz_view): the view restarts it, and the job goes on without it.
        rviz = RvizView(ros, tempfile.mkdtemp(prefix='tutorial_rviz_'), say) if screenshot else None
        if rviz:
            rviz.wait_until_up()
        from std_msgs.msg import Float64
        pos_cmd = rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
        recorder = JointStatesRecorder(rospy)
        run = (FreeRun if free_run else LockstepRun)(ros, rospy, recorder, pos_cmd)
        run.before_controller()
        say('rosrun minimal_joint_controller minimal_joint_controller')
        ros.start(['rosrun', 'minimal_joint_controller', 'minimal_joint_controller'],
                  name='controller')
        # Paused, sim time stands still: wait for the controller's topics before it runs.
        ros.wait_until(lambda: recorder.connected() and pos_cmd.get_num_connections() > 0, 60,
                   what='the controller to publish joint_states and subscribe pos_cmd')
        run.start()
        rows, pd_series, spans = play_phases(
            ros, run, recorder, phases, phase_duration, 'pos_cmd',
            sample_period=None if free_run else CONTROL_PERIOD)
        for number, (phase, series, (start, end)) in enumerate(zip(phases, pd_series, spans), 1):
            plot.write_figure(
                series, os.path.join(output, 'phase%d_%s.png' % (number, phase.name)),
                title='%s: pos_cmd %.1f (%s)' % (phase.name, phase.command, physics_engine),
                xlabel='sim time since the command (s)', until=end - start)
        # From the first command on: whether the controller's first sample (its period on the
        # initial command 0) reaches us depends on how soon our subscription connects.
        t0, end = spans[0][0], spans[-1][1]
        whole = recorder.series(start=t0, origin=t0)
        plot.write_csv(whole, os.path.join(output, 'samples.csv'))
        plot.write_figure(whole, os.path.join(output, 'tutorial.png'),
                          title='The whole tutorial (%s)' % physics_engine,
                          xlabel='sim time (s)', until=end - t0)
        if rviz:
            say('rviz screenshot of the final pose (the table from the collision markers)')
            why = rviz.screenshot(os.path.join(output, SCREENSHOT), refresh=run.refresh)
            rviz.stop()
            if why:
                missing[SCREENSHOT] = why
        rospy.signal_shutdown('tutorial finished')
    in_sim_rows = []
    if in_sim_phase_duration:
        in_sim_rows = play_in_sim_beside(output, physics_engine, in_sim_phase_duration, phases,
                                         rows, pd_series, phase_duration)
    summary = summary_markdown(rows, physics_engine, free_run, in_sim_rows)
    with open(os.path.join(output, 'summary.md'), 'w') as f:
        f.write(summary)
    with open(os.path.join(output, 'summary.json'), 'w') as f:
        json.dump({'physics': physics_engine, 'lockstep': not free_run, 'phases': rows,
                   'in_sim_phases': in_sim_rows}, f, indent=1)
    print(summary)
    say('done in %.1f s of wall time; outputs in %s' % (time.monotonic() - wall_start, output))
    if missing:
        for name, why in missing.items():
            say('%s is missing: %s' % (name, why))
        raise MissingOutputs(missing)
    return rows


if __name__ == '__main__':
    in_sim_main(sys.argv[1:])
