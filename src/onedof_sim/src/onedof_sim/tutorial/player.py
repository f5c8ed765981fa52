"""The main job: plays the tutorial headless on a private ROS graph and writes what a student would
look at. The steps are the tutorial's: launch the simulator with the robot, run the controller,
command 1.0 then 2.0, bring the arm upright (0), insert the cafe table at x = 0.85, command 2.5.
Each phase lasts a fixed span of sim time; the recorder keeps every sample for the plots, the CSV
and the per-phase figures.
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
RECORDED_TOPICS = ('pos_cmd', 'jnt_pos', 'jnt_vel', 'jnt_trq')


def say(text):
    print('[tutorial] ' + text, flush=True)


class Recorder:
    """Keeps (sim time, value) of every recorded std_msgs/Float64 topic, stamped on reception."""

    def __init__(self, rospy):
        from std_msgs.msg import Float64
        self.rospy = rospy
        self.samples = {topic: [] for topic in RECORDED_TOPICS}
        self.subscribers = [rospy.Subscriber('/' + topic, Float64, self._on_sample,
                                             callback_args=topic, queue_size=1000)
                            for topic in RECORDED_TOPICS]

    def connected(self, topic):
        return self.subscribers[RECORDED_TOPICS.index(topic)].get_num_connections() > 0

    def _on_sample(self, msg, topic):
        self.samples[topic].append((self.rospy.get_time(), msg.data))

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


def phase_summary(phase, recorder, start, end):
    positions = recorder.between('jnt_pos', start, end)
    torques = recorder.between('jnt_trq', start, end)
    if len(positions) < 2 or len(torques) < 2:
        raise RuntimeError('phase %s recorded %d positions and %d torques: is the controller '
                           'running?' % (phase.name, len(positions), len(torques)))
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


def summary_markdown(rows, physics_engine):
    lines = ['# Tutorial summary (%s engine)' % physics_engine, '',
             'Predicted: where Kp (c - q) + m g d sin q = 0; with the table, the angle at which '
             'the link first touches the table top. Settling: within 0.02 rad of the settled '
             'angle. Times are sim time.', '',
             '| ' + ' | '.join(title for title, _, _ in SUMMARY_COLUMNS) + ' |',
             '|' + '---|' * len(SUMMARY_COLUMNS)]
    for row in rows:
        lines.append('| ' + ' | '.join(fmt % row[key] for _, key, fmt in SUMMARY_COLUMNS) + ' |')
    return '\n'.join(lines) + '\n'


def play(output, physics_engine, phase_duration=5.0, screenshot=True,
         real_time_factor=1.0):
    """Plays the tutorial; returns the per-phase summary rows. Raises with the reason on failure."""
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
        if real_time_factor != 1.0:
            launch.append('max_update_rate:=%g' % (real_time_factor / DEFAULT_TIME_STEP))
        say(' '.join(launch))
        ros.start(launch, name='launch_simulator')
        os.environ.update(ros.env)
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
        say('rosrun minimal_joint_controller minimal_joint_controller')
        recorder = Recorder(rospy)
        ros.start(['rosrun', 'minimal_joint_controller', 'minimal_joint_controller'],
                  name='controller')
        # Paused, sim time stands still, so the controller's first sample may come before this
        # subscription connects and the next only after unpausing: wait for the connection and
        # for the controller's persistent service connections (one per service on the sim).
        ros.wait_until(lambda: recorder.connected('jnt_pos') and recorder.connected('jnt_trq'), 60,
                       what='the controller to publish jnt_pos and jnt_trq')
        say('rosservice call /gazebo/unpause_physics')
        from std_srvs.srv import Empty
        rospy.ServiceProxy('/gazebo/unpause_physics', Empty)()
        ros.wait_until(lambda: recorder.samples['jnt_pos'], 60, what='the controller on jnt_pos')

        from std_msgs.msg import Float64
        pos_cmd = rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
        rows = []
        for phase in PHASES:
            if phase.before:
                say(' '.join(phase.before))
                result = ros.run(phase.before)
                if result.returncode != 0:
                    raise RuntimeError('%s failed:\n%s%s' % (' '.join(phase.before),
                                                            result.stdout, result.stderr))
            say('rostopic pub pos_cmd std_msgs/Float64 %.1f   (%.0f s of sim time)'
                % (phase.command, phase_duration))
            start = rospy.get_time()
            pos_cmd.publish(Float64(phase.command))
            end = start + phase_duration
            ros.wait_until(lambda: rospy.get_time() >= end, phase_duration * 20 + 30,
                           what='%.0f s of sim time' % phase_duration)
            row = phase_summary(phase, recorder, start, end)
            say('  settled at %.4f rad (predicted %.4f), holding %.3f N m'
                % (row['settled'], row['predicted'], row['holding_torque']))
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
                          xlabel='sim time (s)', until=rospy.get_time() - t0)
        rospy.signal_shutdown('tutorial finished')
    summary = summary_markdown(rows, physics_engine)
    with open(os.path.join(output, 'summary.md'), 'w') as f:
        f.write(summary)
    with open(os.path.join(output, 'summary.json'), 'w') as f:
        json.dump({'physics': physics_engine, 'phases': rows}, f, indent=1)
    print(summary)
    say('done in %.1f s of wall time; outputs in %s' % (time.monotonic() - wall_start, output))
    return rows
