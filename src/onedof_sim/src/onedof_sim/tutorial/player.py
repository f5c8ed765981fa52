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
"""
import collections
import json
import math
import os
import shutil
import subprocess
import tempfile
import time

import yaml

from onedof_sim.tools.plot import held_window
from onedof_sim.tutorial import physics
from onedof_sim.private_ros import PrivateRos

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


class Recorder:
    """Keeps (sim time, value) of what the tutorial plots: pos_cmd as the player commands it, and
    jnt_pos, jnt_vel and jnt_trq from the controller's joint_states (position, velocity, effort),
    each at the sim time its sample was taken (the header stamp: the Float64 topics carry no time,
    and the time of reception says nothing when the simulator runs faster than real time)."""

    def __init__(self, rospy):
        from sensor_msgs.msg import JointState
        self.samples = {topic: [] for topic in RECORDED_TOPICS}
        self.subscriber = rospy.Subscriber('/joint_states', JointState, self._on_joint_state,
                                           queue_size=100000)

    def connected(self):
        return self.subscriber.get_num_connections() > 0

    def _on_joint_state(self, msg):
        if JOINT not in msg.name:
            return
        index = msg.name.index(JOINT)
        t = msg.header.stamp.to_sec()
        for topic, values in (('jnt_pos', msg.position), ('jnt_vel', msg.velocity),
                              ('jnt_trq', msg.effort)):
            if index < len(values):
                self.samples[topic].append((t, values[index]))

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


def free_display():
    for number in range(90, 200):
        if not os.path.exists('/tmp/.X11-unix/X%d' % number) and \
                not os.path.exists('/tmp/.X%d-lock' % number):
            return number
    raise RuntimeError('no free X display number between :90 and :199')


class RvizView:
    """rviz with the committed view (the robot, and the simulated world's other models as collision
    markers), on the user's display or on a private Xvfb, and a screenshot of it once the picture
    stops changing."""

    def __init__(self, ros, work_dir):
        self.ros = ros
        self.env = {}
        if not os.environ.get('DISPLAY'):
            number = free_display()
            self.xvfb = ros.start(['Xvfb', ':%d' % number, '-screen', '0', '1000x720x24',
                                   '-nolisten', 'tcp'], name='xvfb')
            ros.wait_until(lambda: os.path.exists('/tmp/.X11-unix/X%d' % number), 20,
                           what='Xvfb on :%d' % number)
            self.env['DISPLAY'] = ':%d' % number
        self.display = self.env.get('DISPLAY', os.environ.get('DISPLAY'))
        self.config = os.path.join(work_dir, 'tutorial.rviz')
        self._write_config()
        ros.start(['rosrun', 'robot_state_publisher', 'robot_state_publisher'],
                  name='robot_state_publisher')
        self.rviz = ros.start(['rosrun', 'rviz', 'rviz', '-d', self.config], name='rviz',
                              env=dict(self.env, LIBGL_ALWAYS_SOFTWARE='1'))

    def _write_config(self):
        source = subprocess.run(['rospack', 'find', 'minimal_robot_description'],
                                capture_output=True, text=True, check=True).stdout.strip()
        with open(os.path.join(source, 'rviz', 'minimal_robot.rviz')) as f:
            config = yaml.safe_load(f)
        # rviz renders in software here: a few frames a second leave the CPU to the controller.
        config['Visualization Manager']['Global Options']['Frame Rate'] = 5
        with open(self.config, 'w') as f:
            yaml.safe_dump(config, f)

    def _grab(self, path):
        result = subprocess.run(['import', '-display', self.display, '-window', 'root', path],
                                capture_output=True, text=True)
        return result.returncode == 0

    def wait_until_up(self, timeout=90):
        self.ros.wait_until(lambda: self._subscribed('/gazebo/collision_markers'), timeout,
                            what='rviz to subscribe to /gazebo/collision_markers')

    def screenshot(self, path, timeout=90):
        """Waits for rviz to subscribe to the markers, then grabs frames until two in a row are
        the same but for a few pixels (rviz's frame-rate counter) and not blank; keeps that one."""
        self.wait_until_up(timeout)
        previous = path + '.previous.png'

        def steady_frame():
            if os.path.exists(path):
                os.replace(path, previous)
            if not self._grab(path) or is_blank(path) or not os.path.exists(previous):
                return False
            return differing_pixels(path, previous) < STEADY_PIXELS

        self.ros.wait_until(steady_frame, timeout, interval=0.5, what='a steady rviz picture')
        os.remove(previous)

    def _subscribed(self, topic):
        _, _, (publishers, subscribers, _) = self.ros.master().getSystemState('/tutorial')
        return any(name == topic and any('rviz' in node for node in nodes)
                   for name, nodes in subscribers)


# Pixels two frames of a still scene may differ by: rviz's frame-rate counter.
STEADY_PIXELS = 400


def differing_pixels(png_a, png_b):
    result = subprocess.run(['compare', '-metric', 'AE', png_a, png_b, 'null:'],
                            capture_output=True, text=True)
    try:
        return float(result.stderr.split()[0])
    except (IndexError, ValueError):
        return math.inf


def is_blank(png_path):
    result = subprocess.run(['identify', '-format', '%k', png_path], capture_output=True,
                            text=True)
    return result.returncode != 0 or result.stdout.strip() in ('', '1')


def phase_summary(phase, recorder, start, end, lockstep):
    positions = recorder.between('jnt_pos', start, end)
    torques = recorder.between('jnt_trq', start, end)
    if len(positions) < 2 or len(torques) < 2:
        raise RuntimeError('phase %s recorded %d positions and %d torques: is the controller '
                           'running?' % (phase.name, len(positions), len(torques)))
    periods = round((end - start) / CONTROL_PERIOD)
    if lockstep and len(positions) != periods:
        raise RuntimeError('phase %s recorded %d samples in lock-step, not one per period (%d)'
                           % (phase.name, len(positions), periods))
    metrics = physics.step_metrics([t for t, _ in positions], [q for _, q in positions],
                                   start_value=positions[0][1])
    metrics['holding_torque'] = physics.tail_mean([t for t, _ in torques], [u for _, u in torques])
    if phase.before is SPAWN_TABLE:
        predicted = physics.table_contact_angle(TABLE_X)
        metrics['met_table'] = 'tip rim at x = %.3f m, z = %.3f m' % physics.tip_rim(
            metrics['settled'])
        # At rest on the table the rate is 0: the torque is Kp times the remaining error.
        metrics['predicted_torque'] = physics.KP * (phase.command - metrics['settled'])
    else:
        predicted = physics.settled_angle(phase.command)
        metrics['met_table'] = ''
        metrics['predicted_torque'] = -physics.gravity_torque(predicted)
    metrics.update(name=phase.name, command=phase.command, predicted=predicted,
                   samples=len(positions))
    return metrics


SUMMARY_COLUMNS = (
    ('phase', 'name', '%s'), ('command (rad)', 'command', '%.2f'),
    ('settled (rad)', 'settled', '%.4f'), ('predicted (rad)', 'predicted', '%.4f'),
    ('overshoot (rad)', 'overshoot', '%.4f'), ('settling time (s)', 'settling_time', '%.2f'),
    ('holding torque (N m)', 'holding_torque', '%.3f'),
    ('predicted torque (N m)', 'predicted_torque', '%.3f'), ('met the table', 'met_table', '%s'))


def summary_markdown(rows, physics_engine, free_run=False):
    lines = ['# Tutorial summary (%s engine, %s)'
             % (physics_engine, 'free-running' if free_run else 'lock-step'), '',
             'Predicted: where Kp (c - q) + m g d sin q = 0; with the table, the angle at which '
             'the link first touches the table top. Settling: within 0.02 rad of the settled '
             'angle. Times are sim time.', '',
             '| ' + ' | '.join(title for title, _, _ in SUMMARY_COLUMNS) + ' |',
             '|' + '---|' * len(SUMMARY_COLUMNS)]
    for row in rows:
        lines.append('| ' + ' | '.join(fmt % row[key] for _, key, fmt in SUMMARY_COLUMNS) + ' |')
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


def play(output, physics_engine, phase_duration=5.0, screenshot=True, free_run=False,
         real_time_factor=1.0, phases=PHASES):
    """Plays the tutorial's `phases` (a leading part of PHASES: each starts where the one before
    left the arm), in lock-step unless free_run (then paced at real_time_factor); returns the
    per-phase summary rows. Raises with the reason on failure."""
    from onedof_sim.tools import plot
    os.makedirs(output, exist_ok=True)
    log_dir = os.path.join(output, 'logs')
    shutil.rmtree(log_dir, ignore_errors=True)
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
        rviz = RvizView(ros, tempfile.mkdtemp(prefix='tutorial_rviz_')) if screenshot else None
        if rviz:
            rviz.wait_until_up()
        from std_msgs.msg import Float64
        pos_cmd = rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
        recorder = Recorder(rospy)
        run = (FreeRun if free_run else LockstepRun)(ros, rospy, recorder, pos_cmd)
        run.before_controller()
        say('rosrun minimal_joint_controller minimal_joint_controller')
        ros.start(['rosrun', 'minimal_joint_controller', 'minimal_joint_controller'],
                  name='controller')
        # Paused, sim time stands still: wait for the controller's topics before it runs.
        ros.wait_until(lambda: recorder.connected() and pos_cmd.get_num_connections() > 0, 60,
                   what='the controller to publish joint_states and subscribe pos_cmd')
        run.start()
        rows = []
        for phase in phases:
            if phase.before:
                say(' '.join(phase.before))
                result = ros.run(phase.before)
                if result.returncode != 0:
                    raise RuntimeError('%s failed:\n%s%s' % (' '.join(phase.before),
                                                            result.stdout, result.stderr))
            say('rostopic pub pos_cmd std_msgs/Float64 %.1f   (%.0f s of sim time)'
                % (phase.command, phase_duration))
            phase_wall = time.monotonic()
            start, end = run.phase(phase.command, phase_duration)
            row = phase_summary(phase, recorder, start, end, lockstep=not free_run)
            say('  settled at %.4f rad (predicted %.4f), holding %.3f N m; %.1f s of sim time '
                'in %.1f s of wall time' % (row['settled'], row['predicted'],
                                            row['holding_torque'], end - start,
                                            time.monotonic() - phase_wall))
            rows.append(row)
            plot.write_figure(
                recorder.series(start, end, origin=start),
                os.path.join(output, 'phase%d_%s.png' % (len(rows), phase.name)),
                title='%s: pos_cmd %.1f (%s)' % (phase.name, phase.command, physics_engine),
                xlabel='sim time since the command (s)', until=end - start)
        if rviz:
            say('rviz screenshot of the final pose (the table from the collision markers)')
            rviz.screenshot(os.path.join(output, 'rviz_final.png'))
        t0 = recorder.samples['jnt_pos'][0][0]
        plot.write_csv(recorder.series(origin=t0), os.path.join(output, 'samples.csv'))
        plot.write_figure(recorder.series(origin=t0), os.path.join(output, 'tutorial.png'),
                          title='The whole tutorial (%s)' % physics_engine,
                          xlabel='sim time (s)', until=end - t0)
        rospy.signal_shutdown('tutorial finished')
    summary = summary_markdown(rows, physics_engine, free_run)
    with open(os.path.join(output, 'summary.md'), 'w') as f:
        f.write(summary)
    with open(os.path.join(output, 'summary.json'), 'w') as f:
        json.dump({'physics': physics_engine, 'lockstep': not free_run, 'phases': rows}, f,
                  indent=1)
    print(summary)
    say('done in %.1f s of wall time; outputs in %s' % (time.monotonic() - wall_start, output))
    return rows
